/* gltf_fixture.h: small glTF files for the importer's unit tests (test_gltf_load.c,
 * test_scene_gltf.c; header only, after support.h).
 *
 * The fixture is a unit quad in the z = 0 plane: 4 positions, normals (0 0 2: not unit),
 * uvs and 6 UNSIGNED_SHORT indices, in one data-URI buffer of QUAD_BYTES bytes with four
 * buffer views (0 positions, 1 normals, 2 uvs, 3 indices) and accessors of the same
 * numbers. gltf_text() fills the rest of a document from parts a test replaces.
 */
#ifndef RT_GLTF_FIXTURE_H
#define RT_GLTF_FIXTURE_H

#define QUAD_BYTES 144

static const float quad_positions[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
static const float quad_uvs[8] = {0, 1, 1, 1, 1, 0, 0, 0};   /* glTF's: v down */
static const uint16_t quad_indices[6] = {0, 1, 2, 0, 2, 3};

#define QUAD_VIEWS                                                                                     \
    "\"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48}, {\"buffer\": 0, "    \
    "\"byteOffset\": 48, \"byteLength\": 48}, {\"buffer\": 0, \"byteOffset\": 96, \"byteLength\": 32}, " \
    "{\"buffer\": 0, \"byteOffset\": 128, \"byteLength\": 12}]"
#define QUAD_ACCESSORS                                                                                           \
    "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"}, "         \
    "{\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\"}, {\"bufferView\": 2, "     \
    "\"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"}, {\"bufferView\": 3, \"componentType\": 5123, " \
    "\"count\": 6, \"type\": \"SCALAR\"}]"
#define QUAD_MESHES                                                                                          \
    "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"NORMAL\": 1, \"TEXCOORD_0\": 2}, " \
    "\"indices\": 3}]}]"
#define QUAD_NODES "\"nodes\": [{\"mesh\": 0}], \"scenes\": [{\"nodes\": [0]}], \"scene\": 0"

/* The fixture's buffer bytes. */
static inline void quad_buffer(unsigned char out[QUAD_BYTES])
{
    memset(out, 0, QUAD_BYTES);
    memcpy(out, quad_positions, sizeof quad_positions);
    for (int v = 0; v < 4; v++) {
        float normal[3] = {0, 0, 2};
        memcpy(out + 48 + 12 * v, normal, sizeof normal);
    }
    memcpy(out + 96, quad_uvs, sizeof quad_uvs);
    memcpy(out + 128, quad_indices, sizeof quad_indices);
}

/* Returns bytes as base64 (malloc'd; the caller frees it). */
static inline char *base64_of(const unsigned char *bytes, size_t size)
{
    static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char *out = malloc(4 * (size / 3 + 1) + 1);
    size_t n = 0;
    for (size_t i = 0; i < size; i += 3) {
        uint32_t v = (uint32_t)bytes[i] << 16 | (i + 1 < size ? (uint32_t)bytes[i + 1] << 8 : 0) |
                     (i + 2 < size ? bytes[i + 2] : 0);
        out[n++] = digits[v >> 18 & 63];
        out[n++] = digits[v >> 12 & 63];
        out[n++] = i + 1 < size ? digits[v >> 6 & 63] : '=';
        out[n++] = i + 2 < size ? digits[v & 63] : '=';
    }
    out[n] = '\0';
    return out;
}

/* Writes name: a glTF document of the fixture's buffer (bytes, size; NULL for the quad's)
 * and the given parts (NULL for the quad's views, accessors, meshes, nodes); extra is more
 * top-level members (or ""), each part without the surrounding braces. Returns the path
 * (in the scratch's buffer). */
static inline const char *gltf_text(scratch *s, const char *name, const unsigned char *bytes, size_t size,
                                    const char *views, const char *accessors, const char *meshes, const char *nodes,
                                    const char *extra)
{
    unsigned char quad[QUAD_BYTES];
    if (bytes == NULL) {
        quad_buffer(quad);
        bytes = quad;
        size = QUAD_BYTES;
    }
    char *encoded = base64_of(bytes, size);
    size_t length = strlen(encoded) + 16384;
    char *text = malloc(length);
    snprintf(text, length,
             "{\"asset\": {\"version\": \"2.0\"},\n%s,\n%s,\n%s,\n%s,\n%s%s\"buffers\": [{\"byteLength\": %zu, "
             "\"uri\": \"data:application/octet-stream;base64,%s\"}]}\n",
             views != NULL ? views : QUAD_VIEWS, accessors != NULL ? accessors : QUAD_ACCESSORS,
             meshes != NULL ? meshes : QUAD_MESHES, nodes != NULL ? nodes : QUAD_NODES, extra,
             extra[0] != '\0' ? ",\n" : "", size, encoded);
    const char *path = write_file(s, name, text);
    free(encoded);
    free(text);
    return path;
}

#endif
