/* gltf_load.cpp: see gltf_load.h. A thin extern "C" shim over tinygltf; no C++ exception
 * crosses the C boundary.
 *
 * tinygltf parses; this file reads the file itself (for errno's reasons and to tell GLB
 * from JSON by its first bytes), keeps images encoded (an image loader of its own that
 * only copies bytes: decoding is the asset loader's, through OpenImageIO), then checks
 * every index, range, type and number of what tinygltf returns as it turns it into the
 * flat arrays of gltf_load.h. Its parts:
 *   extensions     which are read, which refused, which warned about
 *   accessors      buffer views and accessors read into floats or indices, sparse too
 *   materials      factors, textures (image + sampler), KHR_texture_transform
 *   meshes         primitives to triangle lists, attributes merged per mesh
 * and core/gltf_nodes.cpp walks the default scene's trees (transforms, placements,
 * cameras, lights); gltf_internal.h is what the two share. Every check throws a gltf_failure "WHERE: WHAT" (WHERE a JSON path); load() prefixes
 * the file's path.
 */
#include "gltf_load.h"

#include "gltf_internal.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "packed_layout.h"

/* ------------------------------------------------------------------ shared helpers */

namespace gltf_shim {

[[noreturn]] void fail(const std::string &where, const std::string &what)
{
    throw gltf_failure{where.empty() ? what : where + ": " + what};
}

/* "name[index]", the JSON path of an array element. */
std::string at(const std::string &name, size_t index)
{
    return name + "[" + std::to_string(index) + "]";
}

/* A number for a message, with as few digits as show it. */
std::string number(double value)
{
    char text[40];
    snprintf(text, sizeof text, "%.9g", value);
    return text;
}

/* A whole number (a byte count that may not fit 64 bits) for a message. */
std::string whole(double value)
{
    char text[64];
    snprintf(text, sizeof text, "%.0f", value);
    return text;
}

/* Copies text into a fixed buffer of size bytes, cut to fit. */
void copy_name(char *buffer, size_t size, const std::string &text)
{
    snprintf(buffer, size, "%s", text.c_str());
}

/* Checks that value lies in [low, high]; where names it. */
float checked_factor(double value, double low, double high, const std::string &where)
{
    if (!(value >= low && value <= high))
        fail(where, number(value) + " is outside [" + number(low) + ", " + (std::isinf(high) ? "infinity" : number(high))
                        + "]");
    return (float)value;
}

}  // namespace gltf_shim

namespace {

using namespace gltf_shim;

/* ------------------------------------------------------------------ the file */

/* Reads the whole file; fails with errno's reason when it cannot. */
std::vector<unsigned char> read_file(const char *path)
{
    struct stat info;
    if (stat(path, &info) != 0)
        fail("", strerror(errno));
    if (S_ISDIR(info.st_mode))
        fail("", "it is a directory");
    FILE *file = fopen(path, "rb");
    if (file == nullptr)
        fail("", strerror(errno));
    std::vector<unsigned char> bytes;
    unsigned char buffer[1 << 16];
    size_t n;
    while ((n = fread(buffer, 1, sizeof buffer, file)) > 0)
        bytes.insert(bytes.end(), buffer, buffer + n);
    bool failed = ferror(file) != 0;
    fclose(file);
    if (failed)
        fail("", strerror(EIO));
    return bytes;
}

/* The directory part of path ("" for a bare file name), as tinygltf wants its base. */
std::string directory_of(const std::string &path)
{
    size_t slash = path.find_last_of('/');
    if (slash == std::string::npos)
        return "";
    return slash == 0 ? "/" : path.substr(0, slash);
}

/* Whether path's last component ends in ".glb" (any case). */
bool named_glb(const std::string &path)
{
    if (path.size() < 4)
        return false;
    std::string tail = path.substr(path.size() - 4);
    for (char &c : tail)
        c = (char)tolower((unsigned char)c);
    return tail == ".glb";
}

/* Decodes the %XX escapes of a URI (as tinygltf does before opening an image file). */
std::string percent_decoded(const std::string &uri)
{
    std::string out;
    for (size_t i = 0; i < uri.size(); i++) {
        if (uri[i] == '%' && i + 2 < uri.size() && isxdigit((unsigned char)uri[i + 1]) &&
            isxdigit((unsigned char)uri[i + 2])) {
            out += (char)strtol(uri.substr(i + 1, 2).c_str(), nullptr, 16);
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

/* The image loader tinygltf calls for every image: keeps the encoded bytes. For an image
 * in a buffer view tinygltf passes a pointer into the buffer without checking the view
 * against it, so the view is checked here, on the model being filled, before any read. */
bool keep_image_bytes(tinygltf::Image *image, const int index, std::string *error, std::string *, int, int,
                      const unsigned char *bytes, int size, void *user)
{
    const tinygltf::Model *model = (const tinygltf::Model *)user;
    if (image->bufferView >= 0) {
        const tinygltf::BufferView &view = model->bufferViews[(size_t)image->bufferView];
        const tinygltf::Buffer &buffer = model->buffers[(size_t)view.buffer];
        if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset) {
            *error += "images[" + std::to_string(index) + "]: buffer view " + std::to_string(image->bufferView)
                      + " reads past the end of buffer " + std::to_string(view.buffer) + "\n";
            return false;
        }
        bytes = buffer.data.data() + view.byteOffset;
        size = (int)std::min(view.byteLength, (size_t)INT_MAX);
    }
    if (size > 0)
        image->image.assign(bytes, bytes + size);
    return true;
}

/* Has tinygltf parse bytes (GLB or JSON) into model; fails with its first error line. */
void parse(const std::vector<unsigned char> &bytes, const std::string &path, tinygltf::Model *model,
           context *c)
{
    bool binary = bytes.size() >= 4 && memcmp(bytes.data(), "glTF", 4) == 0;
    if (!binary && named_glb(path))
        fail("", "not a binary glTF file (it does not start with 'glTF')");
    if (bytes.size() > UINT_MAX)
        fail("", "larger than 4 GiB, which tinygltf cannot read");
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(keep_image_bytes, model);
    std::string error, warning;
    const std::string base = directory_of(path);
    bool ok = binary ? loader.LoadBinaryFromMemory(model, &error, &warning, bytes.data(), (unsigned)bytes.size(),
                                                   base)
                     : loader.LoadASCIIFromString(model, &error, &warning, (const char *)bytes.data(),
                                                  (unsigned)bytes.size(), base);
    if (!ok) {
        std::string first = error.substr(0, error.find('\n'));
        fail("", "tinygltf: " + (first.empty() ? std::string("it could not parse the file") : first));
    }
    /* tinygltf warns about an external image it cannot read and leaves it empty; that
     * image is reported with its reason below (check_images), so the warning is dropped. */
    size_t begin = 0;
    while (begin < warning.size()) {
        size_t end = warning.find('\n', begin);
        if (end == std::string::npos)
            end = warning.size();
        std::string line = warning.substr(begin, end - begin);
        begin = end + 1;
        if (!line.empty() && line.find("Failed to load external 'uri' for image") == std::string::npos)
            c->warn("tinygltf: " + line);
    }
}

/* ------------------------------------------------------------------ extensions */

const char *const supported_extensions[] = {
    "KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_transmission",
    "KHR_materials_ior", "KHR_texture_transform", "KHR_mesh_quantization",
};

bool supported(const std::string &name)
{
    for (const char *known : supported_extensions)
        if (name == known)
            return true;
    return false;
}

/* Refuses a required extension that is not read; warns once about optional ones. */
void check_extensions(const tinygltf::Model &model, context *c)
{
    for (size_t i = 0; i < model.extensionsRequired.size(); i++)
        if (!supported(model.extensionsRequired[i]))
            fail(at("extensionsRequired", i), "the extension '" + model.extensionsRequired[i]
                                                  + "' is required but not supported (rtspheres reads "
                                                    "KHR_lights_punctual, KHR_materials_emissive_strength, "
                                                    "KHR_materials_transmission, KHR_materials_ior, "
                                                    "KHR_texture_transform and KHR_mesh_quantization)");
    std::string ignored;
    for (const std::string &name : model.extensionsUsed)
        if (!supported(name))
            ignored += (ignored.empty() ? "" : ", ") + name;
    if (!ignored.empty())
        c->warn("extensionsUsed: optional extensions that are ignored: " + ignored);
}

/* The number at key of an extension object (default when absent); what names it. */
double extension_number(const tinygltf::ExtensionMap &extensions, const char *extension, const char *key,
                        double fallback)
{
    auto found = extensions.find(extension);
    if (found == extensions.end() || !found->second.IsObject())
        return fallback;
    const tinygltf::Value &value = found->second.Get(key);
    return value.IsNumber() ? value.GetNumberAsDouble() : fallback;
}

/* ------------------------------------------------------------------ accessors */

/* The bytes of one component of type, or 0 for a type glTF does not allow. */
int component_size(int type)
{
    switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;
    }
}

/* Reads component (of type) at p as a double, normalised to [-1, 1] or [0, 1] when asked. */
double read_component(const unsigned char *p, int type, bool normalized)
{
    switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        int8_t v;
        memcpy(&v, p, 1);
        return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? p[0] / 255.0 : p[0];
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        memcpy(&v, p, 4);
        return normalized ? v / 4294967295.0 : v;
    }
    default: {
        float v;
        memcpy(&v, p, 4);
        return v;
    }
    }
}

/* Where the elements of an accessor (or of one of its sparse arrays) are: a checked
 * byte range with a stride. */
struct element_source {
    const unsigned char *first = nullptr;   /* nullptr: no buffer view, all zeros */
    size_t stride = 0;
};

/* Checks that count elements of element_size bytes, from offset with stride (0: packed),
 * fit buffer view view_index; what names the accessor in messages. */
element_source locate(const tinygltf::Model &model, const std::string &where, const std::string &what,
                      int view_index, size_t offset, size_t count, size_t element_size, bool strided)
{
    if (view_index < 0 || (size_t)view_index >= model.bufferViews.size())
        fail(where, what + " names buffer view " + std::to_string(view_index) + ", which does not exist (the file has "
                        + std::to_string(model.bufferViews.size()) + ")");
    const tinygltf::BufferView &view = model.bufferViews[(size_t)view_index];
    const std::string view_where = at("bufferViews", (size_t)view_index);
    if (view.buffer < 0 || (size_t)view.buffer >= model.buffers.size())
        fail(view_where, "buffer " + std::to_string(view.buffer) + " does not exist (the file has "
                             + std::to_string(model.buffers.size()) + ")");
    const tinygltf::Buffer &buffer = model.buffers[(size_t)view.buffer];
    if (view.byteOffset > buffer.data.size() || view.byteLength > buffer.data.size() - view.byteOffset)
        fail(view_where, "reads past the end of buffer " + std::to_string(view.buffer) + ": it needs bytes "
                             + std::to_string(view.byteOffset) + " to " + std::to_string(view.byteOffset + view.byteLength)
                             + ", the buffer has " + std::to_string(buffer.data.size()));
    size_t stride = element_size;
    if (strided && view.byteStride != 0) {
        if (view.byteStride < element_size || view.byteStride > 252 || view.byteStride % 4 != 0)
            fail(view_where, "byteStride " + std::to_string(view.byteStride) + " must be a multiple of 4 from "
                                 + std::to_string(std::max<size_t>(element_size, 4)) + " to 252 for " + what);
        stride = view.byteStride;
    }
    /* The last element ends at offset + stride * (count - 1) + element_size; in 64 bits,
     * each term checked, so no count can wrap it round. */
    uint64_t limit = view.byteLength;
    if (count == 0 || offset > limit || count - 1 > (limit - offset) / stride ||
        offset + stride * (uint64_t)(count - 1) + element_size > limit)
        fail(where, what + " reads past the end of buffer view " + std::to_string(view_index) + " (of buffer "
                        + std::to_string(view.buffer) + "): it needs bytes " + std::to_string(offset) + " to "
                        + whole((double)offset + (double)stride * (double)(count - 1) + (double)element_size)
                        + ", the view has " + std::to_string(view.byteLength));
    element_source source;
    source.first = buffer.data.data() + view.byteOffset + offset;
    source.stride = stride;
    return source;
}

/* The types an attribute may have. */
struct accessor_rule {
    std::vector<int> components;         /* allowed component counts (1 = SCALAR, 2 = VEC2 ...) */
    std::vector<int> component_types;    /* allowed component types */
    bool integers_normalized_only;       /* integer component types must be normalized */
};

/* Names a component type in messages. */
std::string component_type_name(int type)
{
    switch (type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE (5120)";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE (5121)";
    case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT (5122)";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT (5123)";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT (5125)";
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT (5126)";
    default: return std::to_string(type);
    }
}

/* Reads accessor index (as what the JSON path where refers to) into floats, components
 * per element, after checking its type against rule; *components_out is its count per
 * element. Applies sparse substitution. Every value must be finite. */
std::vector<double> read_accessor(const tinygltf::Model &model, int index, const std::string &where,
                                  const accessor_rule &rule, int *components_out)
{
    if (index < 0 || (size_t)index >= model.accessors.size())
        fail(where, "accessor " + std::to_string(index) + " does not exist (the file has "
                        + std::to_string(model.accessors.size()) + ")");
    const tinygltf::Accessor &accessor = model.accessors[(size_t)index];
    const std::string what = "accessor " + std::to_string(index);
    int components = tinygltf::GetNumComponentsInType((uint32_t)accessor.type);
    if (std::find(rule.components.begin(), rule.components.end(), components) == rule.components.end())
        fail(where, what + " has the wrong type (" + std::to_string(components > 0 ? components : 0)
                        + " components; expected " + (rule.components[0] == 1 ? "SCALAR" : "VEC" + std::to_string(rule.components[0]))
                        + (rule.components.size() > 1 ? " or VEC" + std::to_string(rule.components[1]) : "") + ")");
    int type = accessor.componentType;
    if (std::find(rule.component_types.begin(), rule.component_types.end(), type) == rule.component_types.end())
        fail(where, what + " has component type " + component_type_name(type) + ", which this attribute cannot have");
    if (rule.integers_normalized_only && type != TINYGLTF_COMPONENT_TYPE_FLOAT && !accessor.normalized)
        fail(where, what + " has integer components that are not normalized");
    if (accessor.count == 0 || accessor.count > (size_t)INT_MAX)
        fail(where, what + " has count " + std::to_string(accessor.count) + " (it must be from 1 to 2147483647)");
    const size_t element_size = (size_t)component_size(type) * (size_t)components;
    std::vector<double> values(accessor.count * (size_t)components, 0.0);
    if (accessor.bufferView >= 0) {
        element_source source = locate(model, where, what, accessor.bufferView, accessor.byteOffset, accessor.count,
                                       element_size, true);
        for (size_t e = 0; e < accessor.count; e++)
            for (int k = 0; k < components; k++)
                values[e * (size_t)components + (size_t)k] =
                    read_component(source.first + e * source.stride + (size_t)k * (size_t)component_size(type), type,
                                   accessor.normalized);
    }
    if (accessor.sparse.isSparse) {
        const std::string sparse_what = what + "'s sparse";
        int count = accessor.sparse.count;
        if (count < 1 || (size_t)count > accessor.count)
            fail(where, sparse_what + " count " + std::to_string(count) + " must be from 1 to the accessor's count "
                            + std::to_string(accessor.count));
        int index_type = accessor.sparse.indices.componentType;
        if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(where, sparse_what + " indices have component type " + component_type_name(index_type)
                            + " (expected an unsigned integer type)");
        if (accessor.sparse.indices.byteOffset < 0 || accessor.sparse.values.byteOffset < 0)
            fail(where, sparse_what + " has a negative byteOffset");
        element_source indices = locate(model, where, sparse_what + " indices", accessor.sparse.indices.bufferView,
                                        (size_t)accessor.sparse.indices.byteOffset, (size_t)count,
                                        (size_t)component_size(index_type), false);
        element_source substitutes = locate(model, where, sparse_what + " values", accessor.sparse.values.bufferView,
                                            (size_t)accessor.sparse.values.byteOffset, (size_t)count, element_size,
                                            false);
        for (size_t i = 0; i < (size_t)count; i++) {
            double target = read_component(indices.first + i * indices.stride, index_type, false);
            if (target >= (double)accessor.count)
                fail(where, sparse_what + " index " + number(target) + " (element " + std::to_string(i)
                                + ") is out of range: the accessor has " + std::to_string(accessor.count)
                                + " elements");
            for (int k = 0; k < components; k++)
                values[(size_t)target * (size_t)components + (size_t)k] = read_component(
                    substitutes.first + i * substitutes.stride + (size_t)k * (size_t)component_size(type), type,
                    accessor.normalized);
        }
    }
    for (size_t i = 0; i < values.size(); i++)
        if (!std::isfinite(values[i]) || std::fabs(values[i]) > 3.4028234663852886e38)
            fail(where, what + " element " + std::to_string(i / (size_t)components) + " is not a finite number");
    *components_out = components;
    return values;
}

/* ------------------------------------------------------------------ materials */

/* The wrap mode of a glTF sampler value, or -1 for one glTF does not define. */
int wrap_mode(int gl_wrap)
{
    switch (gl_wrap) {
    case TINYGLTF_TEXTURE_WRAP_REPEAT: return IMAGE_WRAP_REPEAT;
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return IMAGE_WRAP_CLAMP;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return IMAGE_WRAP_MIRROR;
    default: return -1;
    }
}

/* A texture transform (KHR_texture_transform) as uv' = M (u, v, 1). */
struct uv_transform {
    double m[2][3] = {{1, 0, 0}, {0, 1, 0}};
    bool operator==(const uv_transform &o) const { return memcmp(m, o.m, sizeof m) == 0; }
};

/* Reads the array of n numbers at key of object into out (left as it is when absent);
 * where names the object in messages. */
void value_numbers(const tinygltf::Value &object, const char *key, int n, double *out, const std::string &where)
{
    if (!object.Has(key))
        return;
    const tinygltf::Value &array = object.Get(key);
    if (!array.IsArray() || array.ArrayLen() != (size_t)n)
        fail(where + "." + key, "expected an array of " + std::to_string(n) + " numbers");
    for (int i = 0; i < n; i++) {
        if (!array.Get(i).IsNumber())
            fail(where + "." + key, "expected an array of " + std::to_string(n) + " numbers");
        out[i] = array.Get(i).GetNumberAsDouble();
    }
}

/* The texture of a material (a textureInfo's index and texCoord and extensions) as an
 * image and wrap modes; *transform gets its KHR_texture_transform; warns about texCoord. */
gltf_texture_ref texture_ref(const tinygltf::Model &model, int texture, int texcoord,
                             const tinygltf::ExtensionMap &extensions, const std::string &where, uv_transform *transform,
                             context *c)
{
    gltf_texture_ref ref = {-1, IMAGE_WRAP_REPEAT, IMAGE_WRAP_REPEAT};
    if (texture < 0)
        return ref;
    if ((size_t)texture >= model.textures.size())
        fail(where + ".index", "texture " + std::to_string(texture) + " does not exist (the file has "
                                   + std::to_string(model.textures.size()) + ")");
    const tinygltf::Texture &t = model.textures[(size_t)texture];
    const std::string texture_where = at("textures", (size_t)texture);
    if (t.source < 0)
        fail(texture_where, "the texture has no source image (an extension's image source is not supported)");
    if ((size_t)t.source >= model.images.size())
        fail(texture_where + ".source", "image " + std::to_string(t.source) + " does not exist (the file has "
                                            + std::to_string(model.images.size()) + ")");
    ref.image = t.source;
    if (t.sampler >= 0) {
        if ((size_t)t.sampler >= model.samplers.size())
            fail(texture_where + ".sampler", "sampler " + std::to_string(t.sampler) + " does not exist (the file has "
                                                 + std::to_string(model.samplers.size()) + ")");
        const tinygltf::Sampler &sampler = model.samplers[(size_t)t.sampler];
        ref.wrap_u = wrap_mode(sampler.wrapS);
        ref.wrap_v = wrap_mode(sampler.wrapT);
        if (ref.wrap_u < 0 || ref.wrap_v < 0)
            fail(at("samplers", (size_t)t.sampler), "wrapS and wrapT must be 10497 (REPEAT), 33071 (CLAMP_TO_EDGE) "
                                                    "or 33648 (MIRRORED_REPEAT)");
    }
    *transform = uv_transform();
    auto found = extensions.find("KHR_texture_transform");
    if (found != extensions.end() && found->second.IsObject()) {
        const tinygltf::Value &object = found->second;
        const std::string ext_where = where + ".extensions.KHR_texture_transform";
        double offset[2] = {0, 0}, scale[2] = {1, 1}, rotation = 0;
        value_numbers(object, "offset", 2, offset, ext_where);
        value_numbers(object, "scale", 2, scale, ext_where);
        if (object.Has("rotation")) {
            if (!object.Get("rotation").IsNumber())
                fail(ext_where + ".rotation", "expected a number (radians)");
            rotation = object.Get("rotation").GetNumberAsDouble();
        }
        /* glTF's order: translation x rotation x scale, rotation [cos sin; -sin cos]. */
        double cs = std::cos(rotation), sn = std::sin(rotation);
        transform->m[0][0] = cs * scale[0];
        transform->m[0][1] = sn * scale[1];
        transform->m[0][2] = offset[0];
        transform->m[1][0] = -sn * scale[0];
        transform->m[1][1] = cs * scale[1];
        transform->m[1][2] = offset[1];
        if (object.Has("texCoord") && object.Get("texCoord").IsNumber())
            texcoord = object.Get("texCoord").GetNumberAsInt();
    }
    if (texcoord != 0)
        c->warn(where + ": uses TEXCOORD_" + std::to_string(texcoord) + "; only TEXCOORD_0 is read, so it is used");
    return ref;
}

/* Converts material index; *transform gets the uv transform its textures use. */
gltf_material convert_material(const tinygltf::Model &model, size_t index, uv_transform *transform, context *c)
{
    const tinygltf::Material &m = model.materials[index];
    const std::string where = at("materials", index);
    const std::string pbr = where + ".pbrMetallicRoughness";
    gltf_material out;
    memset(&out, 0, sizeof out);
    copy_name(out.name, sizeof out.name, m.name);
    const std::vector<double> &base = m.pbrMetallicRoughness.baseColorFactor;
    if (base.size() != 4)
        fail(pbr + ".baseColorFactor", "expected 4 numbers, found " + std::to_string(base.size()));
    for (int k = 0; k < 4; k++)
        out.base_color[k] = checked_factor(base[(size_t)k], 0, 1, pbr + ".baseColorFactor");
    out.metallic = checked_factor(m.pbrMetallicRoughness.metallicFactor, 0, 1, pbr + ".metallicFactor");
    out.roughness = checked_factor(m.pbrMetallicRoughness.roughnessFactor, 0, 1, pbr + ".roughnessFactor");
    if (!m.emissiveFactor.empty() && m.emissiveFactor.size() != 3)
        fail(where + ".emissiveFactor", "expected 3 numbers, found " + std::to_string(m.emissiveFactor.size()));
    float strength = checked_factor(extension_number(m.extensions, "KHR_materials_emissive_strength",
                                                     "emissiveStrength", 1.0),
                                    0, INFINITY, where + ".extensions.KHR_materials_emissive_strength.emissiveStrength");
    for (int k = 0; k < 3; k++)
        out.emissive[k] = m.emissiveFactor.empty() ? 0.0f
                          : checked_factor(m.emissiveFactor[(size_t)k], 0, 1, where + ".emissiveFactor") * strength;
    if (m.alphaMode == "OPAQUE")
        out.alpha_mode = GLTF_ALPHA_OPAQUE;
    else if (m.alphaMode == "MASK")
        out.alpha_mode = GLTF_ALPHA_MASK;
    else if (m.alphaMode == "BLEND")
        out.alpha_mode = GLTF_ALPHA_BLEND;
    else
        fail(where + ".alphaMode", "'" + m.alphaMode.substr(0, 40) + "' is not OPAQUE, MASK or BLEND");
    out.alpha_cutoff = checked_factor(m.alphaCutoff, 0, INFINITY, where + ".alphaCutoff");
    out.double_sided = m.doubleSided;
    out.transmission = checked_factor(extension_number(m.extensions, "KHR_materials_transmission",
                                                       "transmissionFactor", 0.0),
                                      0, 1, where + ".extensions.KHR_materials_transmission.transmissionFactor");
    out.ior = checked_factor(extension_number(m.extensions, "KHR_materials_ior", "ior", 1.5), 1, INFINITY,
                             where + ".extensions.KHR_materials_ior.ior");
    auto transmission = m.extensions.find("KHR_materials_transmission");
    if (transmission != m.extensions.end() && transmission->second.Has("transmissionTexture"))
        c->warn(where + ": the transmission texture is ignored (the factor applies everywhere)");

    /* The textures, and the one transform they share (the base colour's first). */
    struct {
        gltf_texture_ref *ref;
        const tinygltf::TextureInfo *info;
        const char *name;
    } slots[] = {
        {&out.base_color_texture, &m.pbrMetallicRoughness.baseColorTexture, ".pbrMetallicRoughness.baseColorTexture"},
        {&out.metallic_roughness_texture, &m.pbrMetallicRoughness.metallicRoughnessTexture,
         ".pbrMetallicRoughness.metallicRoughnessTexture"},
        {&out.emissive_texture, &m.emissiveTexture, ".emissiveTexture"},
    };
    bool have_transform = false, differ = false;
    *transform = uv_transform();
    for (auto &slot : slots) {
        uv_transform own;
        *slot.ref = texture_ref(model, slot.info->index, slot.info->texCoord, slot.info->extensions, where + slot.name,
                                &own, c);
        if (slot.ref->image < 0)
            continue;
        differ |= have_transform && !(own == *transform);
        if (!have_transform)
            *transform = own;
        have_transform = true;
    }
    uv_transform normal_transform;
    out.normal_texture = texture_ref(model, m.normalTexture.index, m.normalTexture.texCoord, m.normalTexture.extensions,
                                     where + ".normalTexture", &normal_transform, c);
    if (out.normal_texture.image >= 0) {
        differ |= have_transform && !(normal_transform == *transform);
        if (!have_transform)
            *transform = normal_transform;
    }
    if (differ)
        c->warn(where + ": its textures have different KHR_texture_transforms; the first one's applies to all");
    return out;
}

/* ------------------------------------------------------------------ meshes */

/* One mesh being assembled from its primitives. */
struct mesh_builder {
    std::vector<float> positions, normals, uvs, colors;
    std::vector<uint32_t> indices;
    std::vector<int> materials;
    bool any_normals = false, any_uvs = false, any_colors = false;
};

/* The corners of a primitive's triangles, as indices into its vertices, in glTF's order
 * for mode (strips alternate their winding, fans turn about the first corner). */
std::vector<uint32_t> triangle_corners(const std::vector<uint32_t> &order, int mode, const std::string &where)
{
    std::vector<uint32_t> corners;
    size_t n = order.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (n % 3 != 0)
            fail(where, std::to_string(n) + " vertices (or indices) are not a whole number of triangles");
        return order;
    }
    for (size_t i = 0; n >= 3 && i < n - 2; i++) {
        if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            corners.push_back(order[i]);
            corners.push_back(order[i + 1 + i % 2]);
            corners.push_back(order[i + 2 - i % 2]);
        } else {
            corners.push_back(order[i + 1]);
            corners.push_back(order[i + 2]);
            corners.push_back(order[0]);
        }
    }
    return corners;
}

/* The unit normal of triangle p0 p1 p2 (zero when degenerate), in double. */
void flat_normal(const float *p0, const float *p1, const float *p2, float out[3])
{
    double e1[3], e2[3];
    for (int i = 0; i < 3; i++) {
        e1[i] = (double)p1[i] - p0[i];
        e2[i] = (double)p2[i] - p0[i];
    }
    double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int i = 0; i < 3; i++)
        out[i] = length > 0 && std::isfinite(length) ? (float)(n[i] / length) : 0.0f;
}

/* Adds primitive p of mesh m (at where) to the mesh being built; transforms holds each
 * material's uv transform; mesh_has_normals says whether any primitive of the mesh has
 * normals. Returns false for a primitive of points or lines. */
bool add_primitive(const tinygltf::Model &model, const tinygltf::Primitive &p, const std::string &where,
                   const std::vector<uv_transform> &transforms, bool mesh_has_normals, mesh_builder *b)
{
    int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP)
        return false;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN)
        fail(where + ".mode", std::to_string(mode) + " is not a primitive mode (0 to 6)");
    if (p.material < -1 || p.material >= (int)model.materials.size())
        fail(where + ".material", "material " + std::to_string(p.material) + " does not exist (the file has "
                                      + std::to_string(model.materials.size()) + ")");
    const int F = TINYGLTF_COMPONENT_TYPE_FLOAT, B = TINYGLTF_COMPONENT_TYPE_BYTE,
              UB = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, S = TINYGLTF_COMPONENT_TYPE_SHORT,
              US = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, UI = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    auto position = p.attributes.find("POSITION");
    if (position == p.attributes.end())
        fail(where + ".attributes", "the primitive has no POSITION");
    int components = 0;
    std::vector<double> positions = read_accessor(model, position->second, where + ".attributes.POSITION",
                                                  {{3}, {F, B, UB, S, US}, false}, &components);
    const size_t vertex_count = positions.size() / 3;
    /* An optional attribute, checked to have the vertices' count. */
    auto optional = [&](const char *name, const accessor_rule &rule, int *n) {
        std::vector<double> values;
        auto found = p.attributes.find(name);
        if (found == p.attributes.end())
            return values;
        values = read_accessor(model, found->second, where + ".attributes." + name, rule, n);
        if (values.size() / (size_t)*n != vertex_count)
            fail(where + ".attributes." + name, "accessor " + std::to_string(found->second) + " has "
                                                    + std::to_string(values.size() / (size_t)*n)
                                                    + " elements, POSITION has " + std::to_string(vertex_count));
        return values;
    };
    int normal_n = 3, uv_n = 2, color_n = 3;
    std::vector<double> normals = optional("NORMAL", {{3}, {F, B, S}, true}, &normal_n);
    std::vector<double> uvs = optional("TEXCOORD_0", {{2}, {F, B, UB, S, US}, false}, &uv_n);
    std::vector<double> colors = optional("COLOR_0", {{3, 4}, {F, UB, US}, true}, &color_n);

    std::vector<uint32_t> order;
    if (p.indices >= 0) {
        int n = 0;
        std::vector<double> indices = read_accessor(model, p.indices, where + ".indices", {{1}, {UB, US, UI}, false}, &n);
        order.reserve(indices.size());
        for (size_t i = 0; i < indices.size(); i++) {
            if (indices[i] >= (double)vertex_count)
                fail(where + ".indices", "index " + number(indices[i]) + " (element " + std::to_string(i)
                                             + " of accessor " + std::to_string(p.indices)
                                             + ") is out of range: the primitive has " + std::to_string(vertex_count)
                                             + " vertices");
            order.push_back((uint32_t)indices[i]);
        }
    } else {
        for (size_t v = 0; v < vertex_count; v++)
            order.push_back((uint32_t)v);
    }
    std::vector<uint32_t> corners = triangle_corners(order, mode, where);
    const uv_transform transform = p.material >= 0 ? transforms[(size_t)p.material] : uv_transform();

    /* A primitive without normals among others with them: its own vertex per corner,
     * with its triangle's flat normal. */
    bool unshared = normals.empty() && mesh_has_normals;
    const size_t base = b->positions.size() / 3;
    if (base + (unshared ? corners.size() : vertex_count) > (size_t)INT_MAX)
        fail(where, "the mesh has more than 2^31 - 1 vertices");
    auto add_vertex = [&](size_t v, const float *flat) {
        for (int k = 0; k < 3; k++)
            b->positions.push_back((float)positions[3 * v + (size_t)k]);
        float n[3] = {0, 0, 0};
        if (!normals.empty()) {
            double x = normals[3 * v], y = normals[3 * v + 1], z = normals[3 * v + 2];
            double length = std::sqrt(x * x + y * y + z * z);
            if (length > 0) {
                n[0] = (float)(x / length);
                n[1] = (float)(y / length);
                n[2] = (float)(z / length);
            }
        } else if (flat != nullptr) {
            memcpy(n, flat, sizeof n);
        }
        b->normals.insert(b->normals.end(), n, n + 3);
        double u = uvs.empty() ? 0 : uvs[2 * v], w = uvs.empty() ? 0 : uvs[2 * v + 1];
        b->uvs.push_back((float)(transform.m[0][0] * u + transform.m[0][1] * w + transform.m[0][2]));
        b->uvs.push_back((float)(1.0 - (transform.m[1][0] * u + transform.m[1][1] * w + transform.m[1][2])));
        for (int k = 0; k < 3; k++)
            b->colors.push_back(colors.empty() ? 1.0f : (float)colors[v * (size_t)color_n + (size_t)k]);
    };
    if (unshared) {
        for (size_t t = 0; t + 2 < corners.size(); t += 3) {
            const size_t first = b->positions.size() / 3;
            float p3[3][3];
            for (int k = 0; k < 3; k++)
                for (int a = 0; a < 3; a++)
                    p3[k][a] = (float)positions[3 * corners[t + (size_t)k] + (size_t)a];
            float flat[3];
            flat_normal(p3[0], p3[1], p3[2], flat);
            for (int k = 0; k < 3; k++) {
                add_vertex(corners[t + (size_t)k], flat);
                b->indices.push_back((uint32_t)(first + (size_t)k));
            }
        }
    } else {
        for (size_t v = 0; v < vertex_count; v++)
            add_vertex(v, nullptr);
        for (uint32_t corner : corners)
            b->indices.push_back((uint32_t)base + corner);
    }
    if (b->indices.size() / 3 > (size_t)INT_MAX)
        fail(where, "the mesh has more than 2^31 - 1 triangles");
    b->materials.insert(b->materials.end(), corners.size() / 3, p.material);
    b->any_normals |= !normals.empty();
    b->any_uvs |= !uvs.empty();
    b->any_colors |= !colors.empty();
    return true;
}

/* Converts mesh index into out; transforms holds each material's uv transform. */
void convert_mesh(const tinygltf::Model &model, size_t index, const std::vector<uv_transform> &transforms,
                  gltf_mesh *out, context *c)
{
    const tinygltf::Mesh &mesh = model.meshes[index];
    const std::string where = at("meshes", index);
    copy_name(out->name, sizeof out->name, mesh.name);
    mesh_builder b;
    bool has_normals = false;
    for (const tinygltf::Primitive &p : mesh.primitives)
        has_normals |= p.attributes.count("NORMAL") > 0 && !(p.mode >= 0 && p.mode <= TINYGLTF_MODE_LINE_STRIP);
    for (size_t i = 0; i < mesh.primitives.size(); i++) {
        const tinygltf::Primitive &p = mesh.primitives[i];
        const std::string primitive_where = where + at(".primitives", i);
        if (!add_primitive(model, p, primitive_where, transforms, has_normals, &b)) {
            if (c->skipped++ == 0)
                c->first_skipped = primitive_where;
        } else if (!p.targets.empty())
            c->warn(primitive_where + ": morph targets are ignored (the base shape is used)");
    }
    out->positions = to_malloc(b.positions);
    out->normals = b.any_normals ? to_malloc(b.normals) : nullptr;
    out->uvs = b.any_uvs ? to_malloc(b.uvs) : nullptr;
    out->colors = b.any_colors ? to_malloc(b.colors) : nullptr;
    out->indices = to_malloc(b.indices);
    out->triangle_materials = to_malloc(b.materials);
    out->vertex_count = (int)(b.positions.size() / 3);
    out->triangle_count = (int)(b.indices.size() / 3);
}
/* ------------------------------------------------------------------ the whole file */

/* Checks that every image has its bytes; an external one that could not be read is
 * reported with errno's reason. */
void check_images(const tinygltf::Model &model, const std::string &path)
{
    for (size_t i = 0; i < model.images.size(); i++) {
        const tinygltf::Image &image = model.images[i];
        if (!image.image.empty())
            continue;
        std::string where = at("images", i);
        if (image.uri.empty())
            fail(where, "the image has no data");
        std::string file = percent_decoded(image.uri);
        std::string directory = directory_of(path);
        if (!file.empty() && file[0] != '/' && !directory.empty())
            file = directory + "/" + file;
        struct stat info;
        const char *why = stat(file.c_str(), &info) != 0 ? strerror(errno)
                          : S_ISDIR(info.st_mode)        ? "it is a directory"
                                                         : "it is empty or cannot be read";
        fail(where, "cannot read '" + file + "': " + why);
    }
}

/* Loads the glTF file at path into out (zeroed by the caller); throws gltf_failure or
 * std::bad_alloc, after which the caller frees out. */
void load(const char *path, gltf_model *out)
{
    context c;
    tinygltf::Model model;
    {
        std::vector<unsigned char> bytes = read_file(path);
        parse(bytes, path, &model, &c);
    }
    check_extensions(model, &c);
    check_images(model, path);

    std::vector<uv_transform> transforms(model.materials.size());
    std::vector<gltf_material> materials;
    for (size_t i = 0; i < model.materials.size(); i++)
        materials.push_back(convert_material(model, i, &transforms[i], &c));

    /* The C arrays are filled as they are made, so that a failure frees what was made. */
    out->materials = to_malloc(materials);
    out->material_count = (int)materials.size();
    if (!model.meshes.empty()) {
        out->meshes = (gltf_mesh *)calloc(model.meshes.size(), sizeof *out->meshes);
        if (out->meshes == nullptr)
            throw std::bad_alloc();
        out->mesh_count = (int)model.meshes.size();
    }
    std::vector<int> triangle_counts(model.meshes.size());
    for (size_t i = 0; i < model.meshes.size(); i++) {
        convert_mesh(model, i, transforms, &out->meshes[i], &c);
        triangle_counts[i] = out->meshes[i].triangle_count;
    }
    if (c.skipped > 0)
        c.warn(c.first_skipped + ": points and lines are not rendered: this primitive"
               + (c.skipped > 1 ? " and " + std::to_string(c.skipped - 1) + " more are" : std::string(" is"))
               + " skipped");
    scene_walk walk = walk_nodes(model, triangle_counts, &c);
    if (walk.placements.empty())
        c.warn("scene: its nodes place no mesh with triangles; nothing of the file is drawn");
    for (size_t n = 0; n < model.nodes.size(); n++)
        if (!model.nodes[n].weights.empty())
            c.warn(at("nodes", n) + ": morph target weights are ignored");
    for (size_t l = 0; l < model.lights.size(); l++)
        if (model.lights[l].range > 0)
            c.warn("extensions.KHR_lights_punctual" + at(".lights", l) + ": range is ignored (lights fall off "
                                                                          "with the inverse square of distance)");
    out->placements = to_malloc(walk.placements);
    out->placement_count = (int)walk.placements.size();
    out->cameras = to_malloc(walk.cameras);
    out->camera_count = (int)walk.cameras.size();
    out->lights = to_malloc(walk.lights);
    out->light_count = (int)walk.lights.size();

    if (!model.images.empty()) {
        out->images = (gltf_image *)calloc(model.images.size(), sizeof *out->images);
        if (out->images == nullptr)
            throw std::bad_alloc();
        out->image_count = (int)model.images.size();
    }
    for (size_t i = 0; i < model.images.size(); i++) {
        tinygltf::Image &image = model.images[i];
        gltf_image *target = &out->images[i];
        std::string name = image.name;
        if (name.empty() && !image.uri.empty() && image.uri.compare(0, 5, "data:") != 0)
            name = image.uri.substr(image.uri.find_last_of('/') + 1);
        copy_name(target->name, sizeof target->name, name);
        target->bytes = to_malloc(image.image);
        target->size = image.image.size();
        std::vector<unsigned char>().swap(image.image);
    }
    out->warning_count = c.warnings.size() > INT_MAX ? INT_MAX : (int)c.warnings.size();
    for (size_t i = 0; i < c.warnings.size() && i < GLTF_MAX_WARNINGS; i++)
        copy_name(out->warnings[i], sizeof out->warnings[i], c.warnings[i]);
}

/* Sets the error "PATH: WHY" and returns status. */
rt_status load_failed(rt_error *error, rt_status status, const char *path, const std::string &why)
{
    return rt_error_set(error, status, "%s: %s", path, why.c_str());
}

}  // namespace

extern "C" {

rt_status gltf_load(const char *path, gltf_model *out, rt_error *error)
{
    if (out == nullptr)
        return rt_error_set(error, RT_ERROR_INPUT, "GLTF: no model to load into");
    memset(out, 0, sizeof *out);
    if (path == nullptr)
        return rt_error_set(error, RT_ERROR_INPUT, "GLTF: no path to read a model from");
    try {
        load(path, out);
        return RT_OK;
    } catch (const gltf_failure &failure) {
        gltf_model_free(out);
        return load_failed(error, RT_ERROR_INPUT, path, failure.reason);
    } catch (const std::bad_alloc &) {
        gltf_model_free(out);
        return load_failed(error, RT_ERROR_RUNTIME, path, "out of memory");
    } catch (const std::exception &e) {
        gltf_model_free(out);
        return load_failed(error, RT_ERROR_INPUT, path, e.what());
    } catch (...) {
        gltf_model_free(out);
        return load_failed(error, RT_ERROR_INPUT, path, "unexpected C++ exception");
    }
}

void gltf_model_free(gltf_model *model)
{
    if (model == nullptr)
        return;
    for (int i = 0; i < model->mesh_count; i++) {
        gltf_mesh *mesh = &model->meshes[i];
        free(mesh->positions);
        free(mesh->normals);
        free(mesh->uvs);
        free(mesh->colors);
        free(mesh->indices);
        free(mesh->triangle_materials);
    }
    free(model->meshes);
    free(model->materials);
    for (int i = 0; i < model->image_count; i++)
        free(model->images[i].bytes);
    free(model->images);
    free(model->placements);
    free(model->cameras);
    free(model->lights);
    memset(model, 0, sizeof *model);
}

}  // extern "C"
