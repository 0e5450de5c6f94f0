/* obj_load.cpp: see obj_load.h. A thin extern "C" shim over tinyobjloader; no C++
 * exception crosses the C boundary.
 *
 * tinyobjloader reads the file: which statements exist, how numbers and indices are read,
 * how faces are triangulated, which MTL file of an `mtllib` line is used. This file only
 * opens the files (so that errors carry errno's reason), hands tinyobjloader the MTL files
 * through a MaterialReader (paths relative to the OBJ file), validates the arrays it
 * returns (indices in range, finite numbers, at least one triangle, counts that fit 32
 * bits) and turns them into the flat mesh of obj_load.h.
 *
 * The legacy LoadObj(istream, MaterialReader) is used rather than tinyobj::ObjReader,
 * which takes no MaterialReader of its own: the reader is what keeps an unreadable MTL
 * file a warning with its reason and the names of `usemtl` lines no MTL file defines.
 *
 * Those names: tinyobjloader gives their faces material -1 and keeps the name only in a
 * warning ("material [ 'NAME' ] not found in .mtl"), but such names are how a mesh refers
 * to the scene's own materials. So when that warning comes, the file is parsed once more,
 * its text preceded by an `mtllib` line of our own for which the reader defines every such
 * name as a placeholder. That second parse changes only the material ids; its line
 * numbers are one off, so every message comes from the first parse.
 */
#include "obj_load.h"

#include <tiny_obj_loader.h>

#include <cctype>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <fstream>
#include <istream>
#include <map>
#include <memory>
#include <new>
#include <streambuf>
#include <string>
#include <unordered_map>
#include <vector>

#include <sys/stat.h>

#include "hash.h"

namespace {

/* A reason the file cannot be loaded: thrown inside, turned into an rt_error at the edge. */
struct obj_failure {
    std::string reason;
};

[[noreturn]] void fail(const std::string &reason)
{
    throw obj_failure{reason};
}

/* Reads the whole file; fails with errno's reason when it cannot. */
std::string read_file(const char *path)
{
    struct stat info;
    if (stat(path, &info) != 0)
        fail(strerror(errno));
    if (S_ISDIR(info.st_mode))
        fail("it is a directory");
    std::unique_ptr<FILE, int (*)(FILE *)> file(fopen(path, "rb"), fclose);
    if (!file)
        fail(strerror(errno));
    std::string text;
    if (S_ISREG(info.st_mode) && info.st_size > 0)
        text.reserve((size_t)info.st_size);
    char buffer[1 << 16];
    size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, file.get())) > 0)
        text.append(buffer, n);
    if (ferror(file.get()))
        fail(strerror(errno ? errno : EIO));
    return text;
}

/* tinyobjloader reads a line only up to a NUL byte and silently drops the rest, so a
 * binary file would load as whatever its first bytes happen to say. Refuses it, naming the
 * line (line ends as tinyobjloader counts them: "\n", "\r\n" or "\r"). */
void refuse_nul_bytes(const std::string &text)
{
    const void *nul = memchr(text.data(), '\0', text.size());
    if (nul == nullptr)
        return;
    size_t at = (size_t)((const char *)nul - text.data());
    size_t line = 1;
    for (size_t i = 0; i < at; i++)
        if (text[i] == '\n' || (text[i] == '\r' && text[i + 1] != '\n'))
            line++;
    fail("line " + std::to_string(line) + ": a NUL byte (is it a binary file?)");
}

/* The directory part of path ("" for a bare file name). */
std::string directory_of(const std::string &path)
{
    size_t slash = path.find_last_of('/');
    if (slash == std::string::npos)
        return "";
    return slash == 0 ? "/" : path.substr(0, slash);
}

/* An istream source over bytes in memory, without a copy. */
struct memory_buffer : std::streambuf {
    memory_buffer(const char *begin, size_t size)
    {
        char *start = const_cast<char *>(begin);
        setg(start, start, start + size);
    }
};

/* Shortens text to show in a message. */
std::string shown(const std::string &text)
{
    return text.size() <= 40 ? text : text.substr(0, 37) + "...";
}

/* Appends item to list unless it is there already. */
void add_unique(std::vector<std::string> &list, const std::string &item)
{
    for (const std::string &existing : list)
        if (existing == item)
            return;
    list.push_back(item);
}

/* The warnings in a tinyobjloader warning string, one per line, as it wrote them. Lines
 * without a letter are left out: it ends some warnings with a stray "." line. */
std::vector<std::string> warning_lines(const std::string &text)
{
    std::vector<std::string> lines;
    size_t begin = 0;
    while (begin < text.size()) {
        size_t end = text.find('\n', begin);
        if (end == std::string::npos)
            end = text.size();
        std::string line = text.substr(begin, end - begin);
        begin = end + 1;
        while (!line.empty() && isspace((unsigned char)line.back()))
            line.pop_back();
        bool has_letter = false;
        for (char c : line)
            has_letter |= isalpha((unsigned char)c) != 0;
        if (has_letter)
            lines.push_back(line);
    }
    return lines;
}

/* The NAME of tinyobjloader's warning "material [ 'NAME' ] not found in .mtl" (a `usemtl`
 * naming no material of a loaded MTL file), or false when line is another warning. */
bool unknown_material_name(const std::string &line, std::string *name)
{
    static const std::string head = "material [ '", tail = "' ] not found in .mtl";
    if (line.size() < head.size() + tail.size() || line.compare(0, head.size(), head) != 0
        || line.compare(line.size() - tail.size(), tail.size(), tail) != 0)
        return false;
    *name = line.substr(head.size(), line.size() - head.size() - tail.size());
    return true;
}

/* The MaterialReader tinyobjloader calls for every file of an `mtllib` line, until one
 * loads. Paths are relative to the OBJ file's directory. With placeholder names, its first
 * call (our own first `mtllib` line) defines each of them as an empty material instead; a
 * later MTL definition of such a name replaces the placeholder from there on. */
class material_libraries : public tinyobj::MaterialReader {
public:
    material_libraries(const std::string &directory, const std::vector<std::string> &placeholders)
        : directory_(directory), placeholders_(placeholders) {}

    bool operator()(const std::string &library, std::vector<tinyobj::material_t> *materials,
                    std::map<std::string, int> *map, std::string *, std::string *) override
    {
        if (!placeholders_.empty() && !placeholders_defined_) {
            placeholders_defined_ = true;
            for (const std::string &name : placeholders_) {
                tinyobj::material_t placeholder = tinyobj::material_t();
                placeholder.name = name;
                map->insert(std::make_pair(name, (int)materials->size()));
                materials->push_back(placeholder);
            }
            return true;
        }
        return load(library, materials, map);
    }

    /* Materials below this index are placeholders (not defined by an MTL file). */
    size_t placeholder_count() const { return placeholders_defined_ ? placeholders_.size() : 0; }
    const std::vector<std::string> &warnings() const { return warnings_; }
    /* Why the materials cannot be used, or "": kept rather than thrown, so that no
     * exception unwinds through tinyobjloader's frames. */
    const std::string &failure() const { return failure_; }

private:
    bool load(const std::string &library, std::vector<tinyobj::material_t> *materials,
              std::map<std::string, int> *map)
    {
        std::string path = library.empty() || library[0] == '/' || directory_.empty()
                               ? library
                               : directory_ + "/" + library;
        struct stat info;
        const char *why = nullptr;
        if (stat(path.c_str(), &info) != 0)
            why = strerror(errno);
        else if (!S_ISREG(info.st_mode))
            why = "not a regular file";
        std::ifstream stream;
        if (why == nullptr) {
            stream.open(path, std::ios::binary);
            if (!stream)
                why = strerror(errno ? errno : EIO);
        }
        if (why != nullptr) {
            add_unique(warnings_, "cannot read material library '" + path + "': " + why
                                      + "; its materials are left out");
            return false;
        }
        size_t first = materials->size();
        std::string warnings, errors;
        tinyobj::LoadMtl(map, materials, &stream, &warnings, &errors);
        for (const std::string &warning : warning_lines(warnings))
            add_unique(warnings_, "tinyobjloader, in '" + path + "': " + warning);
        for (size_t i = first; i < materials->size(); i++) {
            const tinyobj::material_t &m = (*materials)[i];
            float values[] = {m.diffuse[0],  m.diffuse[1],  m.diffuse[2],  m.specular[0],
                              m.specular[1], m.specular[2], m.emission[0], m.emission[1],
                              m.emission[2], m.shininess,   m.ior,         m.dissolve};
            for (float value : values)
                if (!std::isfinite(value) && failure_.empty())
                    failure_ = "material '" + shown(m.name) + "' of '" + path
                               + "' has a value that is not a finite number";
            auto named = map->find(m.name);
            if (named != map->end() && (size_t)named->second < placeholder_count())
                named->second = (int)i;
        }
        return true;
    }

    std::string directory_;
    std::vector<std::string> placeholders_;
    bool placeholders_defined_ = false;
    std::vector<std::string> warnings_;
    std::string failure_;
};

/* What one tinyobjloader parse returned. */
struct parsed_obj {
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    size_t placeholder_count = 0;
    std::vector<std::string> warnings;   /* ours, then tinyobjloader's, each once */
};

/* Has tinyobjloader parse text (with a first `mtllib` line of ours when there are
 * placeholder names, see the top). Fails with tinyobjloader's message when it refuses. */
parsed_obj parse(const std::string &text, const std::string &directory,
                 const std::vector<std::string> &placeholders)
{
    std::string source;
    if (!placeholders.empty())
        source = "mtllib rtspheres:usemtl-placeholders\n" + text;
    const std::string &parsed_text = placeholders.empty() ? text : source;
    memory_buffer buffer(parsed_text.data(), parsed_text.size());
    std::istream stream(&buffer);
    material_libraries libraries(directory, placeholders);
    parsed_obj out;
    std::string warnings, errors;
    bool parsed = tinyobj::LoadObj(&out.attrib, &out.shapes, &out.materials, &warnings, &errors,
                                   &stream, &libraries, true, false);
    if (!parsed) {
        std::vector<std::string> lines = warning_lines(errors);
        fail(lines.empty() ? "tinyobjloader could not parse it" : "tinyobjloader: " + lines[0]);
    }
    if (!libraries.failure().empty())
        fail(libraries.failure());
    out.placeholder_count = libraries.placeholder_count();
    out.warnings = libraries.warnings();
    for (const std::string &warning : warning_lines(warnings))
        add_unique(out.warnings, "tinyobjloader: " + warning);
    return out;
}

/* Checks that every value of an attribute array is finite; what names one element of
 * width values in the message ("vertex 12 has a coordinate that is not a finite number"). */
void check_finite(const std::vector<tinyobj::real_t> &values, size_t width, const char *what)
{
    for (size_t i = 0; i < values.size(); i++)
        if (!std::isfinite(values[i]))
            fail(std::string(what) + " " + std::to_string(i / width + 1)
                 + " has a coordinate that is not a finite number (beyond the range of a float)");
}

/* Checks one index of one triangle corner: -1 (none) is allowed only where optional. */
void check_index(int index, long long count, bool optional, size_t triangle, const char *name,
                 const char *plural)
{
    if (index >= 0 && index < count)
        return;
    if (optional && index == -1)
        return;
    std::string where = "triangle " + std::to_string(triangle + 1) + ": ";
    if (index < 0)
        fail(where + "a relative " + name + " index points before the first " + name);
    fail(where + name + " index " + std::to_string((long long)index + 1)
         + " is out of range: the file has " + std::to_string(count) + " " + plural);
}

/* One output vertex: a position with a normal (an index of the file's, -1 for none, or
 * -2 - t for the geometric normal of triangle t) and a texture coordinate (or -1). Fields
 * ordered so the struct has no padding: it is hashed as bytes. */
struct corner_key {
    int32_t position;
    int32_t uv;
    int64_t normal;
    bool operator==(const corner_key &other) const
    {
        return position == other.position && normal == other.normal && uv == other.uv;
    }
};

/* Hashes a corner_key with the code base's one hash (core/hash.h). */
struct corner_hash {
    size_t operator()(const corner_key &k) const { return (size_t)hash_bytes(HASH_START, &k, sizeof k); }
};

/* Copies a vector into a malloc'd array (NULL for an empty vector). */
template <typename T> T *to_malloc(const std::vector<T> &values)
{
    if (values.empty())
        return nullptr;
    T *copy = (T *)malloc(values.size() * sizeof(T));
    if (copy == nullptr)
        throw std::bad_alloc();
    memcpy(copy, values.data(), values.size() * sizeof(T));
    return copy;
}

/* Makes v unit length, or zero when it is zero. In double, not cglm's float: the squares
 * of floats near the float range (1e38) overflow a float and those of tiny ones (1e-40)
 * underflow it, but not a double, so every finite non-zero v becomes a unit vector
 * (tests/fuzz/regressions/fuzz_obj_load/normal-overflow-near-float-range.obj). */
void normalize(float *v)
{
    double x = v[0], y = v[1], z = v[2];
    double length = std::sqrt(x * x + y * y + z * z);
    if (length > 0 && std::isfinite(length)) {
        v[0] = (float)(x / length);
        v[1] = (float)(y / length);
        v[2] = (float)(z / length);
    } else {
        v[0] = v[1] = v[2] = 0.0f;
    }
}

/* The unit normal of triangle p0 p1 p2 (zero when degenerate), in double and scaled down
 * before the cross product: edges of vertices near the float range (1e38) would overflow a
 * float cross product to inf or NaN. */
void geometric_normal(const float *p0, const float *p1, const float *p2, float out[3])
{
    double e1[3], e2[3], largest = 0;
    for (int i = 0; i < 3; i++) {
        e1[i] = (double)p1[i] - p0[i];
        e2[i] = (double)p2[i] - p0[i];
        largest = std::fmax(largest, std::fmax(std::fabs(e1[i]), std::fabs(e2[i])));
    }
    if (largest > 0)
        for (int i = 0; i < 3; i++) {
            e1[i] /= largest;
            e2[i] /= largest;
        }
    double cross[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
    double length = std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]);
    for (int i = 0; i < 3; i++)
        out[i] = length > 0 ? (float)(cross[i] / length) : 0.0f;
}

/* The mesh's materials: tinyobjloader's, less the unnamed entries it makes of an MTL
 * file's start; material_index maps each of its indices to ours (or -1). */
std::vector<obj_material> convert_materials(const parsed_obj &obj, std::vector<int> *material_index)
{
    std::vector<obj_material> out;
    material_index->assign(obj.materials.size(), -1);
    for (size_t i = 0; i < obj.materials.size(); i++) {
        const tinyobj::material_t &m = obj.materials[i];
        if (m.name.empty())
            continue;
        obj_material o;
        memset(&o, 0, sizeof o);
        snprintf(o.name, sizeof o.name, "%s", m.name.c_str());
        o.defined = i >= obj.placeholder_count;
        o.shininess = 1.0f;
        o.index_of_refraction = 1.0f;
        o.dissolve = 1.0f;
        if (o.defined) {
            for (int c = 0; c < 3; c++) {
                o.diffuse[c] = m.diffuse[c];
                o.specular[c] = m.specular[c];
                o.emission[c] = m.emission[c];
            }
            o.shininess = m.shininess;
            o.index_of_refraction = m.ior;
            o.dissolve = m.dissolve;
        }
        (*material_index)[i] = (int)out.size();
        out.push_back(o);
    }
    return out;
}

/* The triangles tinyobjloader made, in file order, every index checked; their materials
 * (ours) go to triangle_materials. Fails with the first bad index. */
std::vector<tinyobj::index_t> checked_triangles(const parsed_obj &obj, const std::vector<int> &material_index,
                                                std::vector<int> *triangle_materials)
{
    const long long position_count = (long long)(obj.attrib.vertices.size() / 3);
    const long long normal_count = (long long)(obj.attrib.normals.size() / 3);
    const long long uv_count = (long long)(obj.attrib.texcoords.size() / 2);
    std::vector<tinyobj::index_t> corners;
    for (const tinyobj::shape_t &shape : obj.shapes) {
        const tinyobj::mesh_t &mesh = shape.mesh;
        size_t offset = 0;
        for (size_t face = 0; face < mesh.num_face_vertices.size(); face++) {
            size_t triangle = triangle_materials->size();
            if (mesh.num_face_vertices[face] != 3 || offset + 3 > mesh.indices.size())
                fail("tinyobjloader returned face " + std::to_string(triangle + 1) + " with "
                     + std::to_string(mesh.num_face_vertices[face]) + " corners, not a triangle");
            int material = face < mesh.material_ids.size() ? mesh.material_ids[face] : -1;
            if (material < -1 || material >= (int)obj.materials.size())
                fail("tinyobjloader returned a material index out of range");
            for (size_t k = 0; k < 3; k++) {
                const tinyobj::index_t &c = mesh.indices[offset + k];
                check_index(c.vertex_index, position_count, false, triangle, "vertex", "vertices");
                check_index(c.normal_index, normal_count, true, triangle, "normal", "normals");
                check_index(c.texcoord_index, uv_count, true, triangle, "texture coordinate",
                            "texture coordinates");
                corners.push_back(c);
            }
            triangle_materials->push_back(material < 0 ? -1 : material_index[(size_t)material]);
            offset += 3;
        }
    }
    if (triangle_materials->size() > (size_t)INT_MAX)
        fail("more than 2^31 - 1 triangles are not supported");
    return corners;
}

/* Fills out from what tinyobjloader returned (see obj_load.h), checking it first. */
void build_mesh(const parsed_obj &obj, obj_mesh *out)
{
    const std::vector<float> &v = obj.attrib.vertices;
    const std::vector<float> &vn = obj.attrib.normals;
    const std::vector<float> &vt = obj.attrib.texcoords;
    check_finite(v, 3, "vertex");
    check_finite(vn, 3, "normal");
    check_finite(vt, 2, "texture coordinate");
    if (v.size() / 3 > (size_t)INT_MAX || vn.size() / 3 > (size_t)INT_MAX || vt.size() / 2 > (size_t)INT_MAX)
        fail("more than 2^31 - 1 vertices, normals or texture coordinates are not supported");

    std::vector<int> material_index;
    std::vector<obj_material> materials = convert_materials(obj, &material_index);
    std::vector<int> triangle_materials;
    std::vector<tinyobj::index_t> corners = checked_triangles(obj, material_index, &triangle_materials);
    if (triangle_materials.empty()) {
        /* tinyobjloader drops the faces it cannot use (fewer than 3 corners, a quad with an
         * index out of range) with a warning: its warnings say why. */
        std::string why;
        for (const std::string &warning : obj.warnings)
            if (warning.compare(0, 15, "tinyobjloader: ") == 0)
                why += (why.empty() ? " (tinyobjloader made no triangles; it warned: " : "; ") + warning.substr(15);
        fail("has no faces" + (why.empty() ? "" : why + ")"));
    }
    bool any_normal = false, any_uv = false;
    for (const tinyobj::index_t &c : corners) {
        any_normal |= c.normal_index >= 0;
        any_uv |= c.texcoord_index >= 0;
    }

    /* One vertex per distinct corner. */
    std::unordered_map<corner_key, uint32_t, corner_hash> vertex_of;
    std::vector<float> positions, normals, uvs;
    std::vector<uint32_t> indices;
    indices.reserve(corners.size());
    const size_t triangle_count = triangle_materials.size();
    for (size_t t = 0; t < triangle_count; t++) {
        const tinyobj::index_t *c = &corners[3 * t];
        float geometric[3] = {0, 0, 0};
        if (any_normal && (c[0].normal_index < 0 || c[1].normal_index < 0 || c[2].normal_index < 0))
            geometric_normal(&v[3 * (size_t)c[0].vertex_index], &v[3 * (size_t)c[1].vertex_index],
                             &v[3 * (size_t)c[2].vertex_index], geometric);
        for (int k = 0; k < 3; k++) {
            corner_key key = {c[k].vertex_index, any_uv ? c[k].texcoord_index : -1,
                              !any_normal              ? -1LL
                              : c[k].normal_index >= 0 ? (long long)c[k].normal_index
                                                       : -2LL - (long long)t};
            auto found = vertex_of.find(key);
            if (found != vertex_of.end()) {
                indices.push_back(found->second);
                continue;
            }
            if (vertex_of.size() >= (size_t)INT_MAX)
                fail("more than 2^31 - 1 vertices are not supported");
            uint32_t index = (uint32_t)vertex_of.size();
            vertex_of.emplace(key, index);
            indices.push_back(index);
            const float *p = &v[3 * (size_t)key.position];
            positions.insert(positions.end(), p, p + 3);
            if (any_normal) {
                float n[3] = {geometric[0], geometric[1], geometric[2]};
                if (key.normal >= 0) {
                    memcpy(n, &vn[3 * (size_t)key.normal], sizeof n);
                    normalize(n);
                }
                normals.insert(normals.end(), n, n + 3);
            }
            if (any_uv) {
                float uv[2] = {0, 0};
                if (key.uv >= 0)
                    memcpy(uv, &vt[2 * (size_t)key.uv], sizeof uv);
                uvs.insert(uvs.end(), uv, uv + 2);
            }
        }
    }

    out->positions = to_malloc(positions);
    out->normals = to_malloc(normals);
    out->uvs = to_malloc(uvs);
    out->indices = to_malloc(indices);
    out->triangle_materials = to_malloc(triangle_materials);
    out->materials = to_malloc(materials);
    out->vertex_count = (int)vertex_of.size();
    out->triangle_count = (int)triangle_count;
    out->material_count = (int)materials.size();
}

/* Loads the OBJ file at path into out (zeroed by the caller); throws obj_failure or
 * std::bad_alloc, after which the caller frees out. */
void load(const char *path, obj_mesh *out)
{
    std::string text = read_file(path);
    refuse_nul_bytes(text);
    /* tinyobjloader does not know a UTF-8 byte order mark: it would take the first line
     * for an unknown statement and drop it. */
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0)
        text.erase(0, 3);
    const std::string directory = directory_of(path);

    parsed_obj obj = parse(text, directory, {});
    std::vector<std::string> warnings, unknown_names;
    for (const std::string &warning : obj.warnings) {
        std::string name;
        if (warning.compare(0, 15, "tinyobjloader: ") == 0 && unknown_material_name(warning.substr(15), &name))
            add_unique(unknown_names, name);
        else
            warnings.push_back(warning);
    }
    if (!unknown_names.empty()) {
        parsed_obj named = parse(text, directory, unknown_names);
        std::swap(obj.shapes, named.shapes);
        std::swap(obj.materials, named.materials);
        obj.placeholder_count = named.placeholder_count;
    }
    std::string().swap(text);
    obj.warnings = warnings;
    build_mesh(obj, out);
    out->warning_count = warnings.size() > INT_MAX ? INT_MAX : (int)warnings.size();
    for (size_t i = 0; i < warnings.size() && i < OBJ_MAX_WARNINGS; i++)
        snprintf(out->warnings[i], sizeof out->warnings[i], "%s", warnings[i].c_str());
}

/* Sets the error "OBJ: cannot read 'PATH': WHY" and returns status. */
rt_status load_failed(rt_error *error, rt_status status, const char *path, const std::string &why)
{
    return rt_error_set(error, status, "OBJ: cannot read '%s': %s", path, why.c_str());
}

}  // namespace

extern "C" {

rt_status obj_load(const char *path, obj_mesh *out, rt_error *error)
{
    if (out == nullptr)
        return rt_error_set(error, RT_ERROR_INPUT, "OBJ: no mesh to load into");
    memset(out, 0, sizeof *out);
    if (path == nullptr)
        return rt_error_set(error, RT_ERROR_INPUT, "OBJ: no path to read a mesh from");
    try {
        load(path, out);
        return RT_OK;
    } catch (const obj_failure &failure) {
        obj_mesh_free(out);
        return load_failed(error, RT_ERROR_INPUT, path, failure.reason);
    } catch (const std::bad_alloc &) {
        obj_mesh_free(out);
        return load_failed(error, RT_ERROR_RUNTIME, path, "out of memory");
    } catch (const std::exception &e) {
        obj_mesh_free(out);
        return load_failed(error, RT_ERROR_INPUT, path, e.what());
    } catch (...) {
        obj_mesh_free(out);
        return load_failed(error, RT_ERROR_INPUT, path, "unexpected C++ exception");
    }
}

void obj_mesh_free(obj_mesh *mesh)
{
    if (mesh == nullptr)
        return;
    free(mesh->positions);
    free(mesh->normals);
    free(mesh->uvs);
    free(mesh->indices);
    free(mesh->triangle_materials);
    free(mesh->materials);
    memset(mesh, 0, sizeof *mesh);
}

}  // extern "C"
