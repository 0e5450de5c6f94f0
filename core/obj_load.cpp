/* obj_load.cpp: see obj_load.h. A thin extern "C" shim over tinyobjloader; no C++
 * exception crosses the C boundary.
 *
 * tinyobjloader is lenient where a renderer must not be: it reads "nan" or "abc" as 0,
 * keeps out-of-range indices of triangles, and reports an index past the end only as a
 * warning. So the file is read into memory and checked first, line by line, by the same
 * line and statement rules tinyobjloader uses (check_obj_text); then tinyobjloader parses
 * and triangulates the checked text, and every index it returns is checked again against
 * the arrays it built.
 *
 * Materials: tinyobjloader forgets the name of a `usemtl` that no MTL file defines (the
 * faces get material -1), but such names are how a mesh refers to the scene's own
 * materials. So the text handed to tinyobjloader starts with one extra `mtllib` line of
 * our own; our MaterialReader, called for it before any `usemtl`, loads every MTL file
 * the OBJ names and then adds an entry for every other `usemtl` name. The extra line
 * shifts tinyobjloader's line numbers by one, which its error messages are corrected for.
 */
#include "obj_load.h"

#include <tiny_obj_loader.h>

#include <cctype>
#include <cerrno>
#include <cfloat>
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

namespace {

/* A reason the file cannot be loaded: thrown inside, turned into an rt_error at the edge. */
struct obj_failure {
    rt_status status;
    std::string reason;
};

[[noreturn]] void fail(const std::string &reason)
{
    throw obj_failure{RT_ERROR_INPUT, reason};
}

[[noreturn]] void fail_at(size_t line, const std::string &reason)
{
    fail("line " + std::to_string(line) + ": " + reason);
}

/* The name of our own first `mtllib` line; no real file is looked up by it. */
const char *const synthetic_library = "<rtspheres-materials>";

/* The kinds of vertex elements a face corner refers to. */
enum element_kind { POSITION = 0, UV = 1, NORMAL = 2, ELEMENT_KINDS = 3 };
const char *const element_names[ELEMENT_KINDS] = {"vertex", "texture coordinate", "normal"};
const char *const element_plurals[ELEMENT_KINDS] = {"vertices", "texture coordinates", "normals"};

/* What check_obj_text() learns about a file. */
struct obj_summary {
    long long counts[ELEMENT_KINDS] = {0, 0, 0};          /* v, vt, vn lines */
    long long largest[ELEMENT_KINDS] = {0, 0, 0};         /* largest positive index */
    size_t largest_line[ELEMENT_KINDS] = {0, 0, 0};       /* where it is */
    long long faces = 0;
    std::vector<std::string> libraries;                   /* mtllib files, first use order */
    std::vector<std::string> used_names;                  /* usemtl names, first use order */
};

bool is_blank(char c)
{
    return c == ' ' || c == '\t';
}

/* Splits [begin, end) at spaces and tabs (tinyobjloader's separators). */
std::vector<std::string> split_words(const char *begin, const char *end)
{
    std::vector<std::string> words;
    const char *p = begin;
    while (p < end) {
        while (p < end && is_blank(*p))
            p++;
        const char *start = p;
        while (p < end && !is_blank(*p))
            p++;
        if (p > start)
            words.emplace_back(start, p);
    }
    return words;
}

/* Shortens text to show in a message. */
std::string shown(const std::string &text)
{
    return text.size() <= 40 ? text : text.substr(0, 37) + "...";
}

/* Checks that word is a decimal number whose float value is finite. */
void check_number(const std::string &word, size_t line, const char *what)
{
    bool decimal = !word.empty();
    for (char c : word)
        if (!((c >= '0' && c <= '9') || c == '+' || c == '-' || c == '.' || c == 'e' || c == 'E'))
            decimal = false;
    const char *text = word.c_str();
    char *end = nullptr;
    double value = decimal ? strtod(text, &end) : 0.0;
    if (!decimal || end != text + word.size()) {
        std::string lower;
        for (char c : word)
            lower += (char)(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c);
        if (lower.find("nan") != std::string::npos || lower.find("inf") != std::string::npos)
            fail_at(line, std::string(what) + " '" + shown(word) + "' is not a finite number");
        fail_at(line, std::string(what) + " '" + shown(word) + "' is not a number");
    }
    if (!std::isfinite((float)value))
        fail_at(line, std::string(what) + " '" + shown(word)
                          + "' is not a finite number (beyond the range of a float)");
}

/* Checks a v, vt or vn line: between least and most numbers, each finite. */
void check_numbers(const char *begin, const char *end, size_t line, const char *statement,
                   const char *what, size_t least, size_t most)
{
    std::vector<std::string> words = split_words(begin, end);
    if (words.size() < least || words.size() > most) {
        std::string wanted = least == most ? std::to_string(least)
                                           : std::to_string(least) + " to " + std::to_string(most);
        fail_at(line, std::string("'") + statement + "' needs " + wanted + " numbers, found "
                          + std::to_string(words.size()));
    }
    for (const std::string &word : words)
        check_number(word, line, what);
}

/* Parses a face index (an optional sign and decimal digits); fails on anything else. */
long long parse_index(const std::string &text, const std::string &corner, size_t line)
{
    size_t digits = text.size() > 0 && (text[0] == '-' || text[0] == '+') ? 1 : 0;
    bool valid = text.size() > digits;
    for (size_t i = digits; i < text.size(); i++)
        if (text[i] < '0' || text[i] > '9')
            valid = false;
    if (!valid)
        fail_at(line, "face corner '" + shown(corner) + "' is not of the form v, v/vt, v//vn or "
                      "v/vt/vn with whole numbers");
    return strtoll(text.c_str(), nullptr, 10);  /* saturates: check_index reports the range */
}

/* Checks one index of a face corner against what is known at this line. */
void check_index(obj_summary &summary, element_kind kind, long long index, size_t line)
{
    const char *name = element_names[kind];
    if (index == 0)
        fail_at(line, std::string(name) + " index 0 in a face (OBJ indices start at 1)");
    if (index > INT_MAX || index < -(long long)INT_MAX)
        fail_at(line, std::string(name) + " index " + std::to_string(index) + " is out of range");
    if (index > 0) {
        if (index > summary.largest[kind]) {
            summary.largest[kind] = index;
            summary.largest_line[kind] = line;
        }
        return;
    }
    if (summary.counts[kind] + index < 0)
        fail_at(line, "relative " + std::string(name) + " index " + std::to_string(index)
                          + " is out of range: there are " + std::to_string(summary.counts[kind])
                          + " " + element_plurals[kind] + " before this line");
}

/* Checks an f line: at least three corners i, i/j, i//k or i/j/k of valid indices. */
void check_face(obj_summary &summary, const char *begin, const char *end, size_t line)
{
    std::vector<std::string> corners = split_words(begin, end);
    if (corners.size() < 3)
        fail_at(line, "a face needs at least 3 corners, found " + std::to_string(corners.size()));
    for (const std::string &corner : corners) {
        std::vector<std::string> parts(1);
        for (char c : corner) {
            if (c == '/')
                parts.emplace_back();
            else
                parts.back() += c;
        }
        bool valid = parts.size() <= 3 && !parts[0].empty()
                     && (parts.size() != 2 || !parts[1].empty())
                     && (parts.size() != 3 || !parts[2].empty());
        if (!valid)
            fail_at(line, "face corner '" + shown(corner) + "' is not of the form v, v/vt, v//vn "
                          "or v/vt/vn");
        check_index(summary, POSITION, parse_index(parts[0], corner, line), line);
        if (parts.size() >= 2 && !parts[1].empty())
            check_index(summary, UV, parse_index(parts[1], corner, line), line);
        if (parts.size() == 3)
            check_index(summary, NORMAL, parse_index(parts[2], corner, line), line);
    }
    summary.faces++;
}

void add_unique(std::vector<std::string> &list, const std::string &item)
{
    for (const std::string &existing : list)
        if (existing == item)
            return;
    list.push_back(item);
}

/* Checks one line (without its line ending) the way tinyobjloader reads it. */
void check_line(obj_summary &summary, const char *begin, const char *end, size_t line)
{
    const char *p = begin;
    while (p < end && is_blank(*p))
        p++;
    if (p == end || *p == '#')
        return;
    size_t length = (size_t)(end - p);
    auto is_statement = [&](const char *word) {
        size_t n = strlen(word);
        return length >= n && memcmp(p, word, n) == 0 && (length == n || is_blank(p[n]));
    };
    if (is_statement("v")) {
        /* x y z, optionally w or a colour r g b (tinyobjloader's extension) */
        check_numbers(p + 1, end, line, "v", "vertex coordinate", 3, 7);
        if (++summary.counts[POSITION] > INT_MAX)
            fail_at(line, "more than 2^31 - 1 vertices are not supported");
    } else if (is_statement("vn")) {
        check_numbers(p + 2, end, line, "vn", "normal coordinate", 3, 3);
        if (++summary.counts[NORMAL] > INT_MAX)
            fail_at(line, "more than 2^31 - 1 normals are not supported");
    } else if (is_statement("vt")) {
        check_numbers(p + 2, end, line, "vt", "texture coordinate", 1, 3);
        if (++summary.counts[UV] > INT_MAX)
            fail_at(line, "more than 2^31 - 1 texture coordinates are not supported");
    } else if (is_statement("f")) {
        check_face(summary, p + 1, end, line);
    } else if (length >= 6 && memcmp(p, "usemtl", 6) == 0) {
        /* tinyobjloader: the name is the first word after "usemtl" */
        const char *name = p + 6;
        while (name < end && is_blank(*name))
            name++;
        const char *name_end = name;
        while (name_end < end && !is_blank(*name_end))
            name_end++;
        if (name_end > name)
            add_unique(summary.used_names, std::string(name, name_end));
    } else if (length >= 7 && memcmp(p, "mtllib", 6) == 0 && is_blank(p[6])) {
        /* tinyobjloader: file names separated by spaces, '\' escapes the next character */
        std::string name;
        bool escaping = false;
        for (const char *c = p + 7; c <= end; c++) {
            if (c < end && escaping) {
                name += *c;
                escaping = false;
            } else if (c < end && *c == '\\') {
                escaping = true;
            } else if (c == end || is_blank(*c)) {
                if (!name.empty())
                    add_unique(summary.libraries, name);
                name.clear();
            } else {
                name += *c;
            }
        }
    }
    /* Every other statement (o, g, s, l, p, vp, ...) is left to tinyobjloader, which
     * ignores what it does not know. */
}

/* Checks the text of an OBJ file (from offset start), line by line; line endings are
 * "\n", "\r\n" or "\r", as tinyobjloader reads them. */
obj_summary check_obj_text(const std::string &text, size_t start)
{
    obj_summary summary;
    size_t line = 0;
    size_t i = start;
    const size_t n = text.size();
    while (i < n) {
        size_t begin = i;
        while (i < n && text[i] != '\n' && text[i] != '\r')
            i++;
        size_t end = i;
        if (i < n)
            i += text[i] == '\r' && i + 1 < n && text[i + 1] == '\n' ? 2 : 1;
        line++;
        check_line(summary, text.data() + begin, text.data() + end, line);
    }
    for (int kind = 0; kind < ELEMENT_KINDS; kind++)
        if (summary.largest[kind] > summary.counts[kind])
            fail_at(summary.largest_line[kind],
                    std::string(element_names[kind]) + " index "
                        + std::to_string(summary.largest[kind]) + " is out of range: the file has "
                        + std::to_string(summary.counts[kind]) + " " + element_plurals[kind]);
    if (summary.faces == 0)
        fail("has no faces");
    return summary;
}

/* Reads the whole file. */
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

/* The directory part of path ("" for a bare file name). */
std::string directory_of(const std::string &path)
{
    size_t slash = path.find_last_of('/');
    if (slash == std::string::npos)
        return "";
    return slash == 0 ? "/" : path.substr(0, slash);
}

/* An istream source over a string's bytes, without a copy. */
struct memory_buffer : std::streambuf {
    explicit memory_buffer(const std::string &text)
    {
        char *begin = const_cast<char *>(text.data());
        setg(begin, begin, begin + text.size());
    }
};

/* The lines of a tinyobjloader message (warnings come several to a string, some with a
 * stray "." line), trimmed of trailing spaces and dots, empty ones left out; each "line N"
 * and "line: N" number less shift (1 for the OBJ file, whose text has our extra first
 * line; 0 for an MTL file). */
std::vector<std::string> tinyobj_lines(const std::string &message, unsigned long long shift)
{
    std::vector<std::string> lines;
    size_t begin = 0;
    while (begin <= message.size()) {
        size_t end = message.find('\n', begin);
        if (end == std::string::npos)
            end = message.size();
        std::string line = message.substr(begin, end - begin), out;
        begin = end + 1;
        size_t i = 0;
        while (i < line.size()) {
            size_t digits = line.compare(i, 5, "line ") == 0 ? i + 5 : line.compare(i, 6, "line: ") == 0 ? i + 6 : 0;
            if (digits != 0 && digits < line.size() && isdigit((unsigned char)line[digits])) {
                size_t j = digits;
                unsigned long long number = 0;
                while (j < line.size() && isdigit((unsigned char)line[j]))
                    number = number * 10 + (unsigned long long)(line[j++] - '0');
                out += line.substr(i, digits - i) + std::to_string(number > shift ? number - shift : 0);
                i = j;
            } else {
                out += line[i++];
            }
        }
        while (!out.empty() && (out.back() == ' ' || out.back() == '.' || out.back() == '\r'))
            out.pop_back();
        if (!out.empty())
            lines.push_back(out);
    }
    return lines;
}

/* Loads the MTL files and adds the usemtl-only names, on its first call (our own first
 * mtllib line); later calls (the file's own mtllib lines) have nothing left to do. */
class material_loader : public tinyobj::MaterialReader {
public:
    material_loader(const std::string &directory, const obj_summary &summary)
        : directory_(directory), summary_(summary) {}

    bool operator()(const std::string &, std::vector<tinyobj::material_t> *materials,
                    std::map<std::string, int> *map, std::string *, std::string *) override
    {
        if (loaded_)
            return true;
        loaded_ = true;
        for (const std::string &library : summary_.libraries)
            load_library(library, materials, map);
        defined_count_ = materials->size();
        for (const std::string &name : summary_.used_names) {
            if (map->count(name) != 0)
                continue;
            tinyobj::material_t placeholder = tinyobj::material_t();
            placeholder.name = name;
            map->insert(std::make_pair(name, (int)materials->size()));
            materials->push_back(placeholder);
        }
        return true;
    }

    size_t defined_count() const { return defined_count_; }
    const std::vector<std::string> &warnings() const { return warnings_; }
    const std::string &failure() const { return failure_; }

private:
    void load_library(const std::string &library, std::vector<tinyobj::material_t> *materials,
                      std::map<std::string, int> *map)
    {
        std::string path = library[0] == '/' || directory_.empty() ? library
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
            return;
        }
        size_t first = materials->size();
        std::string warnings, errors;
        tinyobj::LoadMtl(map, materials, &stream, &warnings, &errors);
        for (const std::string &warning : tinyobj_lines(warnings, 0))
            add_unique(warnings_, "tinyobjloader, in '" + path + "': " + warning);
        for (size_t i = first; i < materials->size() && failure_.empty(); i++) {
            const tinyobj::material_t &m = (*materials)[i];
            float values[] = {m.diffuse[0],  m.diffuse[1],  m.diffuse[2],  m.specular[0],
                              m.specular[1], m.specular[2], m.emission[0], m.emission[1],
                              m.emission[2], m.shininess,   m.ior,         m.dissolve};
            for (float value : values)
                if (!std::isfinite(value) && failure_.empty())
                    failure_ = "material '" + shown(m.name) + "' of '" + path
                               + "' has a value that is not a finite number";
        }
    }

    std::string directory_;
    const obj_summary &summary_;
    bool loaded_ = false;
    size_t defined_count_ = 0;
    std::vector<std::string> warnings_;
    std::string failure_;
};

/* The first line of a tinyobjloader error message, its line numbers corrected for our
 * extra first line. */
std::string tinyobj_message(const std::string &message)
{
    std::vector<std::string> lines = tinyobj_lines(message, 1);
    return lines.empty() ? "tinyobjloader could not parse it" : "tinyobjloader: " + lines[0];
}

/* One output vertex: a position with a normal (an index of the file's, or -2 - t for the
 * geometric normal of triangle t) and a texture coordinate (or -1). */
struct corner_key {
    int position;
    long long normal;
    int uv;
    bool operator==(const corner_key &other) const
    {
        return position == other.position && normal == other.normal && uv == other.uv;
    }
};

struct corner_hash {
    size_t operator()(const corner_key &k) const
    {
        uint64_t h = (uint64_t)(uint32_t)k.position * 0x9E3779B97F4A7C15ull;
        h ^= (uint64_t)k.normal * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
        h ^= (uint64_t)(uint32_t)k.uv * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
        return (size_t)h;
    }
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

/* Makes v unit length, or zero when it is zero. In double: the squares of floats near
 * the float range (1e38) overflow a float and those of tiny ones (1e-40) underflow it,
 * but not a double, so every finite non-zero v becomes a unit vector. */
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

/* Fills out from what tinyobjloader returned, checking every index. */
void build_mesh(const tinyobj::attrib_t &attrib, const std::vector<tinyobj::shape_t> &shapes,
                const std::vector<tinyobj::material_t> &materials, size_t defined_count,
                obj_mesh *out)
{
    const std::vector<float> &v = attrib.vertices;
    const std::vector<float> &vn = attrib.normals;
    const std::vector<float> &vt = attrib.texcoords;
    for (const std::vector<float> *values : {&v, &vn, &vt})
        for (float value : *values)
            if (!std::isfinite(value))
                fail("a coordinate is not a finite number");
    const long long position_count = (long long)(v.size() / 3);
    const long long normal_count = (long long)(vn.size() / 3);
    const long long uv_count = (long long)(vt.size() / 2);

    /* Materials: drop unnamed entries (tinyobjloader makes one of an MTL file's start). */
    std::vector<int> material_index(materials.size(), -1);
    std::vector<obj_material> out_materials;
    for (size_t i = 0; i < materials.size(); i++) {
        const tinyobj::material_t &m = materials[i];
        if (m.name.empty())
            continue;
        obj_material o;
        memset(&o, 0, sizeof o);
        snprintf(o.name, sizeof o.name, "%s", m.name.c_str());
        o.defined = i < defined_count;
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
        material_index[i] = (int)out_materials.size();
        out_materials.push_back(o);
    }

    /* Triangles, in file order: corners (position, normal, uv) as tinyobjloader made them. */
    std::vector<tinyobj::index_t> corners;
    std::vector<int> triangle_materials;
    bool any_normal = false, any_uv = false;
    for (const tinyobj::shape_t &shape : shapes) {
        const tinyobj::mesh_t &mesh = shape.mesh;
        size_t offset = 0;
        for (size_t face = 0; face < mesh.num_face_vertices.size(); face++) {
            size_t count = mesh.num_face_vertices[face];
            if (offset + count > mesh.indices.size())
                fail("tinyobjloader returned a face past the end of its index list");
            int material = face < mesh.material_ids.size() ? mesh.material_ids[face] : -1;
            if (material < -1 || material >= (int)materials.size())
                fail("tinyobjloader returned a material index out of range");
            int out_material = material < 0 ? -1 : material_index[(size_t)material];
            for (size_t k = 0; k < count; k++) {
                const tinyobj::index_t &c = mesh.indices[offset + k];
                if (c.vertex_index < 0 || c.vertex_index >= position_count)
                    fail("a face refers to vertex " + std::to_string((long long)c.vertex_index + 1)
                         + ", out of range: the file has " + std::to_string(position_count)
                         + " vertices");
                if (c.normal_index < -1 || c.normal_index >= normal_count)
                    fail("a face refers to normal " + std::to_string((long long)c.normal_index + 1)
                         + ", out of range: the file has " + std::to_string(normal_count)
                         + " normals");
                if (c.texcoord_index < -1 || c.texcoord_index >= uv_count)
                    fail("a face refers to texture coordinate "
                         + std::to_string((long long)c.texcoord_index + 1)
                         + ", out of range: the file has " + std::to_string(uv_count)
                         + " texture coordinates");
                any_normal |= c.normal_index >= 0;
                any_uv |= c.texcoord_index >= 0;
            }
            /* With triangulation on every face is a triangle; a fan covers anything else. */
            for (size_t k = 1; count >= 3 && k + 1 < count; k++) {
                corners.push_back(mesh.indices[offset]);
                corners.push_back(mesh.indices[offset + k]);
                corners.push_back(mesh.indices[offset + k + 1]);
                triangle_materials.push_back(out_material);
            }
            offset += count;
        }
    }
    if (triangle_materials.empty())
        fail("has no faces (tinyobjloader made no triangles of them)");
    if (triangle_materials.size() > (size_t)INT_MAX)
        fail("more than 2^31 - 1 triangles are not supported");

    /* One vertex per distinct corner. */
    std::unordered_map<corner_key, uint32_t, corner_hash> vertex_of;
    std::vector<float> positions, normals, uvs;
    std::vector<uint32_t> indices;
    indices.reserve(corners.size());
    const size_t triangle_count = triangle_materials.size();
    for (size_t t = 0; t < triangle_count; t++) {
        const tinyobj::index_t *c = &corners[3 * t];
        float geometric[3] = {0, 0, 0};
        bool need_geometric = any_normal && (c[0].normal_index < 0 || c[1].normal_index < 0
                                             || c[2].normal_index < 0);
        if (need_geometric) {
            const float *p0 = &v[3 * (size_t)c[0].vertex_index];
            const float *p1 = &v[3 * (size_t)c[1].vertex_index];
            const float *p2 = &v[3 * (size_t)c[2].vertex_index];
            /* In double, scaled down before the cross product: edges of vertices near the
             * float range (1e38) would overflow a float cross product to inf or NaN. */
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
            if (length > 0)
                for (int i = 0; i < 3; i++)
                    geometric[i] = (float)(cross[i] / length);
        }
        for (int k = 0; k < 3; k++) {
            corner_key key = {c[k].vertex_index,
                              !any_normal              ? -1LL
                              : c[k].normal_index >= 0 ? (long long)c[k].normal_index
                                                       : -2LL - (long long)t,
                              any_uv ? c[k].texcoord_index : -1};
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
                    const float *file_normal = &vn[3 * (size_t)key.normal];
                    n[0] = file_normal[0];
                    n[1] = file_normal[1];
                    n[2] = file_normal[2];
                    normalize(n);
                }
                normals.insert(normals.end(), n, n + 3);
            }
            if (any_uv) {
                float uv[2] = {0, 0};
                if (key.uv >= 0) {
                    uv[0] = vt[2 * (size_t)key.uv];
                    uv[1] = vt[2 * (size_t)key.uv + 1];
                }
                uvs.insert(uvs.end(), uv, uv + 2);
            }
        }
    }

    out->positions = to_malloc(positions);
    out->normals = to_malloc(normals);
    out->uvs = to_malloc(uvs);
    out->indices = to_malloc(indices);
    out->triangle_materials = to_malloc(triangle_materials);
    out->materials = to_malloc(out_materials);
    out->vertex_count = (int)vertex_of.size();
    out->triangle_count = (int)triangle_count;
    out->material_count = (int)out_materials.size();
}

void load(const char *path, obj_mesh *out)
{
    std::string text = read_file(path);
    const void *nul = memchr(text.data(), '\0', text.size());
    if (nul != nullptr) {
        size_t at = (size_t)((const char *)nul - text.data());
        size_t line = 1;
        for (size_t i = 0; i < at; i++)
            if (text[i] == '\n' || (text[i] == '\r' && (i + 1 >= text.size() || text[i + 1] != '\n')))
                line++;
        fail_at(line, "a NUL byte (is it a binary file?)");
    }
    const size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;  /* a UTF-8 BOM */
    obj_summary summary = check_obj_text(text, start);

    std::string source = std::string("mtllib ") + synthetic_library + "\n";
    source.append(text, start, std::string::npos);
    std::string().swap(text);
    memory_buffer buffer(source);
    std::istream stream(&buffer);
    material_loader loader(directory_of(path), summary);
    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warnings, errors;
    bool parsed = tinyobj::LoadObj(&attrib, &shapes, &materials, &warnings, &errors, &stream,
                                   &loader, true, false);
    if (!parsed)
        fail(tinyobj_message(errors));
    if (!loader.failure().empty())
        fail(loader.failure());
    std::string().swap(source);
    build_mesh(attrib, shapes, materials, loader.defined_count(), out);
    std::vector<std::string> found = loader.warnings();
    for (const std::string &warning : tinyobj_lines(warnings, 1))
        add_unique(found, "tinyobjloader: " + warning);
    out->warning_count = found.size() > INT_MAX ? INT_MAX : (int)found.size();
    for (size_t i = 0; i < found.size() && i < OBJ_MAX_WARNINGS; i++)
        snprintf(out->warnings[i], sizeof out->warnings[i], "%s", found[i].c_str());
}

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
        return load_failed(error, failure.status, path, failure.reason);
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
