/* models.c: writes the glTF, PLY and OBJ files the importers' tests and the benchmark use
 * (the tests write them into their scratch directories; only model.glb is committed, as
 * scenes/assets/model.glb, the golden suite's glTF scene, which test-importers.sh checks
 * is this generator's output byte for byte).
 *
 * Build and run from the repository root:
 *   cc -std=c11 -O2 scenes/generators/models.c -lm -o /tmp/models && /tmp/models DIR
 * and, for the benchmark's large meshes:
 *   /tmp/models DIR big N      writes only DIR/big.glb and DIR/big.ply: a torus of at least
 *                              N triangles (a grid of quads, two triangles each)
 *
 * Self-contained: C11, libc and libm only; deterministic (every number written is a float
 * printed with 9 significant digits, which reads back as the same float).
 *
 * The torus (the shape every file but model.* shares): major radius 1, minor radius 0.4,
 * about +Y, centred at the origin; TORUS_AROUND x TORUS_TUBE quads on a grid of
 * (TORUS_AROUND + 1) x (TORUS_TUBE + 1) vertices (the seams doubled for the uvs), each
 * vertex with its analytic unit normal and uv (i / TORUS_AROUND, j / TORUS_TUBE): powers of
 * two, so that 1 - v is exact in float and glTF's flipped v (v_gltf = 1 - v) reads back as
 * the very same uv. Quad (i, j) is the corners a b c d (counter-clockwise seen from
 * outside) and its triangles are (a b c) and (a c d): what a PLY reader's fan gives.
 *
 * `models DIR` writes (DIR is created when missing):
 *   torus.obj          the torus as triangles, one v/vt/vn index per corner
 *   torus-ascii.ply    the torus as quads (property list uchar int vertex_indices) with
 *   torus-le.ply       x y z nx ny nz s t and red green blue (uchar) per vertex, plus a
 *   torus-be.ply       property and an element a mesh does not use (to be skipped):
 *                      ASCII, binary little endian and binary big endian, the same values
 *   checker.png        8x8 RGB checker of two colours (an uncompressed PNG)
 *   single.gltf        the torus placed once (node at the identity), material "clay"
 *                      (base colour 0.7 0.3 0.2, metallic 0, roughness 0.5), data-URI buffer
 *   pair.gltf          the same torus placed by two nodes: "left" at translation
 *                      PAIR_LEFT, "right" at PAIR_RIGHT scaled by PAIR_SCALE, both children
 *                      of "pair" at PAIR_ROOT; a perspective camera "view" at
 *                      PAIR_CAMERA looking down -Z, yfov 40 degrees, aspect ratio 2
 *   model.gltf + model.bin, model-embedded.gltf, model.glb
 *                      one richer scene in the three containers (external buffer and
 *                      image file, data URIs, GLB with the image in a buffer view): the
 *                      torus with a textured material (checker.png, MIRRORED_REPEAT x
 *                      CLAMP_TO_EDGE sampler, a KHR_texture_transform scale of 2) placed
 *                      by a node with a matrix under a node with TRS; a panel mesh of a
 *                      triangle strip (indexed), a triangle fan (not indexed, with COLOR_0)
 *                      and a points primitive (skipped by importers); an emissive material
 *                      (KHR_materials_emissive_strength 4) and a glass one
 *                      (KHR_materials_transmission 1, KHR_materials_ior 1.45); cameras
 *                      "front" and "top"; KHR_lights_punctual lights: a point light
 *                      (20 cd), a spot (inner 0.3, outer 0.6 radians) and a directional
 *                      one (3 lx). MODEL_TRIANGLES counts its triangles.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define PI 3.14159265358979323846
#define TORUS_AROUND 32
#define TORUS_TUBE 16
#define TORUS_MAJOR 1.0
#define TORUS_MINOR 0.4

/* ------------------------------------------------------------------ memory and files */

/* A growable byte buffer. */
typedef struct buffer {
    unsigned char *data;
    size_t size, capacity;
} buffer;

static void *checked_realloc(void *p, size_t size)
{
    void *q = realloc(p, size);
    if (q == NULL) {
        fprintf(stderr, "models: out of memory\n");
        exit(1);
    }
    return q;
}

static void put(buffer *b, const void *data, size_t size)
{
    if (b->size + size > b->capacity) {
        b->capacity = (b->size + size) * 2 + 1024;
        b->data = checked_realloc(b->data, b->capacity);
    }
    memcpy(b->data + b->size, data, size);
    b->size += size;
}

static void put_u8(buffer *b, unsigned v)
{
    unsigned char c = (unsigned char)v;
    put(b, &c, 1);
}

/* Appends v in little (big = 0) or big endian order. */
static void put_u16(buffer *b, unsigned v, int big)
{
    unsigned char c[2] = {(unsigned char)(big ? v >> 8 : v), (unsigned char)(big ? v : v >> 8)};
    put(b, c, 2);
}

static void put_u32(buffer *b, uint32_t v, int big)
{
    for (int i = 0; i < 4; i++)
        put_u8(b, (unsigned)(v >> (big ? 24 - 8 * i : 8 * i)));
}

static void put_f32(buffer *b, float f, int big)
{
    uint32_t bits;
    memcpy(&bits, &f, sizeof bits);
    put_u32(b, bits, big);
}

/* Appends printf-formatted text (no NUL). */
static void putf(buffer *b, const char *format, ...) __attribute__((format(printf, 2, 3)));
static void putf(buffer *b, const char *format, ...)
{
    char text[4096];
    va_list arguments;
    va_start(arguments, format);
    int n = vsnprintf(text, sizeof text, format, arguments);
    va_end(arguments);
    if (n < 0 || (size_t)n >= sizeof text) {
        fprintf(stderr, "models: a line longer than %zu bytes\n", sizeof text);
        exit(1);
    }
    put(b, text, (size_t)n);
}

static void pad4(buffer *b, unsigned char with)
{
    while (b->size % 4 != 0)
        put(b, &with, 1);
}

static const char *output_directory;

/* Writes b to DIR/name. */
static void write_file(const char *name, const buffer *b)
{
    char path[4096];
    snprintf(path, sizeof path, "%s/%s", output_directory, name);
    FILE *f = fopen(path, "wb");
    if (f == NULL || fwrite(b->data, 1, b->size, f) != b->size || fclose(f) != 0) {
        fprintf(stderr, "models: cannot write %s: %s\n", path, strerror(errno));
        exit(1);
    }
}

/* ------------------------------------------------------------------ encodings */

static uint32_t crc32_of(const unsigned char *data, size_t size, uint32_t crc)
{
    crc = ~crc;
    for (size_t i = 0; i < size; i++) {
        crc ^= data[i];
        for (int k = 0; k < 8; k++)
            crc = crc & 1 ? (crc >> 1) ^ 0xEDB88320u : crc >> 1;
    }
    return ~crc;
}

/* Appends a PNG chunk of type (4 letters) and data. */
static void png_chunk(buffer *png, const char *type, const buffer *data)
{
    put_u32(png, (uint32_t)data->size, 1);
    size_t start = png->size;
    put(png, type, 4);
    put(png, data->data, data->size);
    put_u32(png, crc32_of(png->data + start, png->size - start, 0), 1);
}

/* An 8-bit RGB PNG of rgb (rows top to bottom), its pixels in stored (uncompressed)
 * deflate blocks: no compressor needed. */
static buffer png_of(int width, int height, const unsigned char *rgb)
{
    buffer raw = {0}, z = {0}, png = {0}, header = {0}, end = {0};
    for (int y = 0; y < height; y++) {
        put_u8(&raw, 0);
        put(&raw, rgb + (size_t)y * (size_t)width * 3, (size_t)width * 3);
    }
    put_u8(&z, 0x78);
    put_u8(&z, 0x01);
    for (size_t at = 0; at < raw.size || at == 0;) {
        size_t n = raw.size - at > 65535 ? 65535 : raw.size - at;
        put_u8(&z, at + n == raw.size ? 1 : 0);
        put_u16(&z, (unsigned)n, 0);
        put_u16(&z, (unsigned)(~n & 0xFFFF), 0);
        put(&z, raw.data + at, n);
        at += n;
        if (n == 0)
            break;
    }
    uint32_t a = 1, b = 0;
    for (size_t i = 0; i < raw.size; i++) {
        a = (a + raw.data[i]) % 65521;
        b = (b + a) % 65521;
    }
    put_u32(&z, b << 16 | a, 1);
    put(&png, "\x89PNG\r\n\x1a\n", 8);
    put_u32(&header, (uint32_t)width, 1);
    put_u32(&header, (uint32_t)height, 1);
    const unsigned char depth_type[5] = {8, 2, 0, 0, 0};
    put(&header, depth_type, 5);
    png_chunk(&png, "IHDR", &header);
    png_chunk(&png, "IDAT", &z);
    png_chunk(&png, "IEND", &end);
    free(raw.data);
    free(z.data);
    free(header.data);
    return png;
}

/* The checker image of checker.png. */
static buffer checker_png(void)
{
    unsigned char rgb[8 * 8 * 3];
    for (int y = 0; y < 8; y++)
        for (int x = 0; x < 8; x++) {
            unsigned char *p = rgb + (y * 8 + x) * 3;
            int odd = (x + y) & 1;
            p[0] = odd ? 230 : 40;
            p[1] = odd ? 200 : 90;
            p[2] = odd ? 60 : 160;
        }
    return png_of(8, 8, rgb);
}

/* Appends b as base64 to out. */
static void put_base64(buffer *out, const buffer *b)
{
    static const char digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    for (size_t i = 0; i < b->size; i += 3) {
        uint32_t v = (uint32_t)b->data[i] << 16;
        if (i + 1 < b->size)
            v |= (uint32_t)b->data[i + 1] << 8;
        if (i + 2 < b->size)
            v |= b->data[i + 2];
        char quad[4] = {digits[v >> 18 & 63], digits[v >> 12 & 63], i + 1 < b->size ? digits[v >> 6 & 63] : '=',
                        i + 2 < b->size ? digits[v & 63] : '='};
        put(out, quad, 4);
    }
}

/* ------------------------------------------------------------------ the torus */

typedef struct mesh {
    float *positions, *normals, *uvs;
    unsigned char *colors;       /* 3 per vertex */
    int vertex_count;
    uint32_t *quads;             /* 4 per quad, counter-clockwise from outside */
    int quad_count;
} mesh;

/* The torus of around x tube quads (see the top). */
static mesh torus(int around, int tube)
{
    mesh m = {0};
    m.vertex_count = (around + 1) * (tube + 1);
    m.positions = checked_realloc(NULL, (size_t)m.vertex_count * 3 * sizeof(float));
    m.normals = checked_realloc(NULL, (size_t)m.vertex_count * 3 * sizeof(float));
    m.uvs = checked_realloc(NULL, (size_t)m.vertex_count * 2 * sizeof(float));
    m.colors = checked_realloc(NULL, (size_t)m.vertex_count * 3);
    for (int i = 0; i <= around; i++)
        for (int j = 0; j <= tube; j++) {
            int v = i * (tube + 1) + j;
            double phi = 2 * PI * i / around, theta = 2 * PI * j / tube;
            double nx = cos(theta) * cos(phi), ny = sin(theta), nz = -cos(theta) * sin(phi);
            double ring = TORUS_MAJOR + TORUS_MINOR * cos(theta);
            m.positions[3 * v] = (float)(ring * cos(phi));
            m.positions[3 * v + 1] = (float)(TORUS_MINOR * sin(theta));
            m.positions[3 * v + 2] = (float)(-ring * sin(phi));
            m.normals[3 * v] = (float)nx;
            m.normals[3 * v + 1] = (float)ny;
            m.normals[3 * v + 2] = (float)nz;
            m.uvs[2 * v] = (float)i / (float)around;
            m.uvs[2 * v + 1] = (float)j / (float)tube;
            m.colors[3 * v] = (unsigned char)(255 * i / around);
            m.colors[3 * v + 1] = (unsigned char)(255 * j / tube);
            m.colors[3 * v + 2] = 128;
        }
    m.quad_count = around * tube;
    m.quads = checked_realloc(NULL, (size_t)m.quad_count * 4 * sizeof(uint32_t));
    for (int i = 0; i < around; i++)
        for (int j = 0; j < tube; j++) {
            uint32_t *q = m.quads + 4 * (i * tube + j);
            uint32_t a = (uint32_t)(i * (tube + 1) + j);
            /* phi grows clockwise seen from +Y (z = -sin), theta outwards then up: this
             * order is counter-clockwise seen from outside. */
            q[0] = a;
            q[1] = a + (uint32_t)(tube + 1);
            q[2] = a + (uint32_t)(tube + 1) + 1;
            q[3] = a + 1;
        }
    return m;
}

static void free_mesh(mesh *m)
{
    free(m->positions);
    free(m->normals);
    free(m->uvs);
    free(m->colors);
    free(m->quads);
}

/* The triangle list of the quads: (a b c) and (a c d) each. */
static uint32_t *triangles_of(const mesh *m)
{
    uint32_t *t = checked_realloc(NULL, (size_t)m->quad_count * 6 * sizeof(uint32_t));
    for (int q = 0; q < m->quad_count; q++) {
        const uint32_t *c = m->quads + 4 * q;
        uint32_t tri[6] = {c[0], c[1], c[2], c[0], c[2], c[3]};
        memcpy(t + 6 * q, tri, sizeof tri);
    }
    return t;
}

static void write_obj(const char *name, const mesh *m)
{
    buffer b = {0};
    putf(&b, "# %s: written by scenes/generators/models.c: the torus, %d triangles\n", name, 2 * m->quad_count);
    for (int v = 0; v < m->vertex_count; v++)
        putf(&b, "v %.9g %.9g %.9g\n", m->positions[3 * v], m->positions[3 * v + 1], m->positions[3 * v + 2]);
    for (int v = 0; v < m->vertex_count; v++)
        putf(&b, "vt %.9g %.9g\n", m->uvs[2 * v], m->uvs[2 * v + 1]);
    for (int v = 0; v < m->vertex_count; v++)
        putf(&b, "vn %.9g %.9g %.9g\n", m->normals[3 * v], m->normals[3 * v + 1], m->normals[3 * v + 2]);
    uint32_t *t = triangles_of(m);
    for (int k = 0; k < 2 * m->quad_count; k++)
        putf(&b, "f %u/%u/%u %u/%u/%u %u/%u/%u\n", t[3 * k] + 1, t[3 * k] + 1, t[3 * k] + 1, t[3 * k + 1] + 1,
             t[3 * k + 1] + 1, t[3 * k + 1] + 1, t[3 * k + 2] + 1, t[3 * k + 2] + 1, t[3 * k + 2] + 1);
    write_file(name, &b);
    free(t);
    free(b.data);
}

typedef enum ply_format { PLY_ASCII, PLY_LITTLE, PLY_BIG } ply_format;

/* Writes the mesh as PLY quads (with_extras: a skipped property and element, see top). */
static void write_ply(const char *name, const mesh *m, ply_format format, int with_extras)
{
    static const char *const formats[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    buffer b = {0};
    int big = format == PLY_BIG;
    putf(&b, "ply\nformat %s 1.0\ncomment written by scenes/generators/models.c\n", formats[format]);
    putf(&b, "element vertex %d\nproperty float x\nproperty float y\nproperty float z\n", m->vertex_count);
    putf(&b, "property float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\n");
    putf(&b, "property uchar red\nproperty uchar green\nproperty uchar blue\n");
    if (with_extras)
        putf(&b, "property double confidence\n");
    putf(&b, "element face %d\nproperty list uchar int vertex_indices\n", m->quad_count);
    if (with_extras)
        putf(&b, "element edge 1\nproperty int vertex1\nproperty int vertex2\nproperty list ushort float weights\n");
    putf(&b, "end_header\n");
    for (int v = 0; v < m->vertex_count; v++) {
        const float *p = m->positions + 3 * v, *n = m->normals + 3 * v, *uv = m->uvs + 2 * v;
        const unsigned char *c = m->colors + 3 * v;
        if (format == PLY_ASCII) {
            putf(&b, "%.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %u %u %u%s\n", p[0], p[1], p[2], n[0], n[1], n[2],
                 uv[0], uv[1], c[0], c[1], c[2], with_extras ? " 0.5" : "");
            continue;
        }
        float values[8] = {p[0], p[1], p[2], n[0], n[1], n[2], uv[0], uv[1]};
        for (int k = 0; k < 8; k++)
            put_f32(&b, values[k], big);
        put(&b, c, 3);
        if (with_extras) {
            double half = 0.5;
            unsigned char bytes[8];
            memcpy(bytes, &half, 8);
            for (int k = 0; k < 8; k++)
                put_u8(&b, bytes[big ? 7 - k : k]);
        }
    }
    for (int q = 0; q < m->quad_count; q++) {
        const uint32_t *c = m->quads + 4 * q;
        if (format == PLY_ASCII) {
            putf(&b, "4 %u %u %u %u\n", c[0], c[1], c[2], c[3]);
            continue;
        }
        put_u8(&b, 4);
        for (int k = 0; k < 4; k++)
            put_u32(&b, c[k], big);
    }
    if (with_extras) {
        if (format == PLY_ASCII) {
            putf(&b, "0 1 2 0.25 0.75\n");
        } else {
            put_u32(&b, 0, big);
            put_u32(&b, 1, big);
            put_u16(&b, 2, big);
            put_f32(&b, 0.25f, big);
            put_f32(&b, 0.75f, big);
        }
    }
    write_file(name, &b);
    free(b.data);
}

/* ------------------------------------------------------------------ glTF */

typedef enum container { EXTERNAL, DATA_URIS, BINARY } container;

/* A glTF document being made: its binary buffer and its bufferViews and accessors. */
typedef struct gltf {
    buffer bin, views, accessors;
    int view_count, accessor_count;
} gltf;

/* Adds a buffer view of size bytes of data; returns its index. */
static int add_view(gltf *g, const void *data, size_t size)
{
    pad4(&g->bin, 0);
    putf(&g->views, "%s{\"buffer\": 0, \"byteOffset\": %zu, \"byteLength\": %zu}", g->view_count ? ", " : "",
         g->bin.size, size);
    put(&g->bin, data, size);
    return g->view_count++;
}

/* Adds an accessor of count elements of type (SCALAR, VEC2, ...) of component (glTF's
 * number) over view; min/max (3 values) for positions, else NULL. Returns its index. */
static int add_accessor(gltf *g, int view, int component, int count, const char *type, const float *min,
                        const float *max, int normalized)
{
    putf(&g->accessors, "%s{\"bufferView\": %d, \"componentType\": %d, \"count\": %d, \"type\": \"%s\"%s",
         g->accessor_count ? ", " : "", view, component, count, type, normalized ? ", \"normalized\": true" : "");
    if (min != NULL)
        putf(&g->accessors, ", \"min\": [%.9g, %.9g, %.9g], \"max\": [%.9g, %.9g, %.9g]", min[0], min[1], min[2],
             max[0], max[1], max[2]);
    put(&g->accessors, "}", 1);
    return g->accessor_count++;
}

/* Adds the positions (3 floats each) of count vertices with their bounds. */
static int add_positions(gltf *g, const float *positions, int count)
{
    float min[3] = {INFINITY, INFINITY, INFINITY}, max[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int v = 0; v < count; v++)
        for (int k = 0; k < 3; k++) {
            min[k] = fminf(min[k], positions[3 * v + k]);
            max[k] = fmaxf(max[k], positions[3 * v + k]);
        }
    int view = add_view(g, positions, (size_t)count * 3 * sizeof(float));
    return add_accessor(g, view, 5126, count, "VEC3", min, max, 0);
}

/* The torus's accessors: POSITION, NORMAL, TEXCOORD_0 (v flipped) and indices. */
typedef struct torus_accessors {
    int position, normal, uv, indices;
} torus_accessors;

static torus_accessors add_torus(gltf *g, const mesh *m)
{
    torus_accessors a;
    a.position = add_positions(g, m->positions, m->vertex_count);
    a.normal = add_accessor(g, add_view(g, m->normals, (size_t)m->vertex_count * 3 * sizeof(float)), 5126,
                            m->vertex_count, "VEC3", NULL, NULL, 0);
    float *flipped = checked_realloc(NULL, (size_t)m->vertex_count * 2 * sizeof(float));
    for (int v = 0; v < m->vertex_count; v++) {
        flipped[2 * v] = m->uvs[2 * v];
        flipped[2 * v + 1] = 1.0f - m->uvs[2 * v + 1];
    }
    a.uv = add_accessor(g, add_view(g, flipped, (size_t)m->vertex_count * 2 * sizeof(float)), 5126, m->vertex_count,
                        "VEC2", NULL, NULL, 0);
    free(flipped);
    uint32_t *t = triangles_of(m);
    int count = 6 * m->quad_count;
    if (m->vertex_count <= 65535) {
        uint16_t *small = checked_realloc(NULL, (size_t)count * sizeof(uint16_t));
        for (int i = 0; i < count; i++)
            small[i] = (uint16_t)t[i];
        a.indices = add_accessor(g, add_view(g, small, (size_t)count * sizeof(uint16_t)), 5123, count, "SCALAR",
                                 NULL, NULL, 0);
        free(small);
    } else {
        a.indices = add_accessor(g, add_view(g, t, (size_t)count * sizeof(uint32_t)), 5125, count, "SCALAR", NULL,
                                 NULL, 0);
    }
    free(t);
    return a;
}

/* Writes the document (its JSON: the body after the buffers, views and accessors, which
 * this adds) as name in the container; the image (may be NULL) is checker.png. */
static void write_gltf(const char *name, gltf *g, const char *body, container kind, const buffer *image)
{
    int image_view = -1;
    if (image != NULL && kind == BINARY)
        image_view = add_view(g, image->data, image->size);
    pad4(&g->bin, 0);
    buffer json = {0};
    putf(&json, "{\"asset\": {\"version\": \"2.0\", \"generator\": \"rtspheres scenes/generators/models.c\"},\n");
    putf(&json, "%s,\n", body);
    if (image != NULL) {
        if (kind == EXTERNAL)
            putf(&json, "\"images\": [{\"uri\": \"checker.png\"}],\n");
        else if (kind == BINARY)
            putf(&json, "\"images\": [{\"bufferView\": %d, \"mimeType\": \"image/png\"}],\n", image_view);
        else {
            putf(&json, "\"images\": [{\"uri\": \"data:image/png;base64,");
            put_base64(&json, image);
            putf(&json, "\"}],\n");
        }
    }
    putf(&json, "\"buffers\": [{\"byteLength\": %zu", g->bin.size);
    if (kind == EXTERNAL) {
        char bin_name[256];
        snprintf(bin_name, sizeof bin_name, "%.*s.bin", (int)(strlen(name) - 5), name);
        putf(&json, ", \"uri\": \"%s\"", bin_name);
        write_file(bin_name, &g->bin);
    } else if (kind == DATA_URIS) {
        putf(&json, ", \"uri\": \"data:application/octet-stream;base64,");
        put_base64(&json, &g->bin);
        put(&json, "\"", 1);
    }
    putf(&json, "}],\n\"bufferViews\": [");
    put(&json, g->views.data, g->views.size);
    putf(&json, "],\n\"accessors\": [");
    put(&json, g->accessors.data, g->accessors.size);
    putf(&json, "]}\n");
    if (kind != BINARY) {
        write_file(name, &json);
    } else {
        pad4(&json, ' ');
        buffer glb = {0};
        put(&glb, "glTF", 4);
        put_u32(&glb, 2, 0);
        put_u32(&glb, (uint32_t)(12 + 8 + json.size + 8 + g->bin.size), 0);
        put_u32(&glb, (uint32_t)json.size, 0);
        put(&glb, "JSON", 4);
        put(&glb, json.data, json.size);
        put_u32(&glb, (uint32_t)g->bin.size, 0);
        put(&glb, "BIN\0", 4);
        put(&glb, g->bin.data, g->bin.size);
        write_file(name, &glb);
        free(glb.data);
    }
    free(json.data);
}

static void free_gltf(gltf *g)
{
    free(g->bin.data);
    free(g->views.data);
    free(g->accessors.data);
}

/* The pair's placements (see the top). */
#define PAIR_ROOT "0, 0.5, 0"
#define PAIR_LEFT "-1.25, 0, 0"
#define PAIR_RIGHT "1.5, 0.25, -0.5"
#define PAIR_SCALE "0.5, 0.5, 0.5"
#define PAIR_CAMERA "0, 1.5, 6"

/* single.gltf (pair 0) or pair.gltf (pair 1). */
static void write_torus_model(const char *name, const mesh *m, int pair)
{
    gltf g = {0};
    torus_accessors a = add_torus(&g, m);
    buffer body = {0};
    putf(&body, "\"scene\": 0, \"scenes\": [{\"nodes\": [%s]}],\n", pair ? "0, 3" : "0");
    if (pair)
        putf(&body, "\"nodes\": [{\"name\": \"pair\", \"translation\": [" PAIR_ROOT "], \"children\": [1, 2]},\n"
                    "  {\"name\": \"left\", \"mesh\": 0, \"translation\": [" PAIR_LEFT "]},\n"
                    "  {\"name\": \"right\", \"mesh\": 0, \"translation\": [" PAIR_RIGHT "], \"scale\": [" PAIR_SCALE
                    "]},\n  {\"name\": \"view\", \"camera\": 0, \"translation\": [" PAIR_CAMERA "]}],\n"
                    "\"cameras\": [{\"name\": \"view\", \"type\": \"perspective\", \"perspective\": "
                    "{\"yfov\": %.17g, \"aspectRatio\": 2, \"znear\": 0.1}}],\n", 40 * PI / 180);
    else
        putf(&body, "\"nodes\": [{\"name\": \"torus\", \"mesh\": 0}],\n");
    putf(&body, "\"materials\": [{\"name\": \"clay\", \"pbrMetallicRoughness\": {\"baseColorFactor\": "
                "[0.7, 0.3, 0.2, 1], \"metallicFactor\": 0, \"roughnessFactor\": 0.5}}],\n");
    putf(&body, "\"meshes\": [{\"name\": \"torus\", \"primitives\": [{\"attributes\": {\"POSITION\": %d, "
                "\"NORMAL\": %d, \"TEXCOORD_0\": %d}, \"indices\": %d, \"material\": 0}]}]",
         a.position, a.normal, a.uv, a.indices);
    put(&body, "", 1);
    write_gltf(name, &g, (const char *)body.data, DATA_URIS, NULL);
    free(body.data);
    free_gltf(&g);
}

/* The triangles of model.*: the torus, the strip's two and the fan's three. */
#define MODEL_TRIANGLES (2 * TORUS_AROUND * TORUS_TUBE + 2 + 3)

/* model.gltf, model-embedded.gltf or model.glb (see the top). */
static void write_rich_model(const char *name, const mesh *m, container kind, const buffer *image)
{
    gltf g = {0};
    torus_accessors a = add_torus(&g, m);
    /* The panel: a strip of 4 vertices (2 triangles), indexed; a fan of 5 (3 triangles),
     * not indexed, with vertex colours; 3 points. */
    const float strip[] = {-1, 0, 0, 1, 0, 0, -1, 1, 0, 1, 1, 0};
    const uint16_t strip_order[] = {0, 1, 2, 3};
    const float fan[] = {0, 2, 0, 1, 2, 0, 0.7f, 2.7f, 0, 0, 3, 0, -0.7f, 2.7f, 0};
    const float fan_colors[] = {1, 1, 1, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 0};
    const float points[] = {0, -1, 0, 0.5f, -1, 0, 1, -1, 0};
    int strip_position = add_positions(&g, strip, 4);
    int strip_indices = add_accessor(&g, add_view(&g, strip_order, sizeof strip_order), 5123, 4, "SCALAR", NULL,
                                     NULL, 0);
    int fan_position = add_positions(&g, fan, 5);
    int fan_color = add_accessor(&g, add_view(&g, fan_colors, sizeof fan_colors), 5126, 5, "VEC3", NULL, NULL, 0);
    int point_position = add_positions(&g, points, 3);
    buffer body = {0};
    putf(&body, "\"extensionsUsed\": [\"KHR_lights_punctual\", \"KHR_materials_emissive_strength\", "
                "\"KHR_materials_transmission\", \"KHR_materials_ior\", \"KHR_texture_transform\"],\n");
    putf(&body, "\"extensions\": {\"KHR_lights_punctual\": {\"lights\": [\n"
                "  {\"name\": \"lamp\", \"type\": \"point\", \"color\": [1, 0.9, 0.8], \"intensity\": 20},\n"
                "  {\"name\": \"spot\", \"type\": \"spot\", \"intensity\": 40, \"spot\": {\"innerConeAngle\": 0.3, "
                "\"outerConeAngle\": 0.6}},\n"
                "  {\"name\": \"sun\", \"type\": \"directional\", \"color\": [1, 1, 0.9], \"intensity\": 3}]}},\n");
    putf(&body, "\"scene\": 0, \"scenes\": [{\"name\": \"main\", \"nodes\": [0, 2, 3, 4, 5, 6, 7]}],\n");
    putf(&body, "\"nodes\": [\n"
                "  {\"name\": \"base\", \"translation\": [0, 0.5, 0], \"rotation\": [0, 0.258819045, 0, 0.965925826], "
                "\"scale\": [1, 1, 1], \"children\": [1]},\n"
                "  {\"name\": \"ring\", \"mesh\": 0, \"matrix\": [1, 0, 0, 0,  0, 0, 1, 0,  0, -1, 0, 0,  0, 0.5, 0, 1]},\n"
                "  {\"name\": \"panel\", \"mesh\": 1, \"translation\": [0, 0, -2]},\n"
                "  {\"name\": \"front\", \"camera\": 0, \"translation\": [0, 1.5, 6]},\n"
                "  {\"name\": \"top\", \"camera\": 1, \"translation\": [0, 8, 0], \"rotation\": [-0.707106781, 0, 0, "
                "0.707106781]},\n"
                "  {\"name\": \"lamp\", \"translation\": [2, 3, 2], \"extensions\": {\"KHR_lights_punctual\": "
                "{\"light\": 0}}},\n"
                "  {\"name\": \"spot\", \"translation\": [0, 4, 0], \"rotation\": [-0.707106781, 0, 0, 0.707106781], "
                "\"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}},\n"
                "  {\"name\": \"sun\", \"rotation\": [-0.5, 0.5, 0.5, 0.5], \"extensions\": "
                "{\"KHR_lights_punctual\": {\"light\": 2}}}],\n");
    putf(&body, "\"cameras\": [{\"name\": \"front\", \"type\": \"perspective\", \"perspective\": {\"yfov\": 0.7, "
                "\"aspectRatio\": 1.5, \"znear\": 0.1}},\n"
                "  {\"name\": \"top\", \"type\": \"perspective\", \"perspective\": {\"yfov\": 0.9, \"znear\": 0.1}}],\n");
    putf(&body, "\"samplers\": [{\"wrapS\": 33648, \"wrapT\": 33071}],\n\"textures\": [{\"sampler\": 0, "
                "\"source\": 0}],\n");
    putf(&body, "\"materials\": [\n"
                "  {\"name\": \"checker\", \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0, "
                "\"extensions\": {\"KHR_texture_transform\": {\"scale\": [2, 2]}}}, \"metallicFactor\": 0, "
                "\"roughnessFactor\": 0.6}},\n"
                "  {\"name\": \"glow\", \"emissiveFactor\": [1, 0.8, 0.5], \"extensions\": "
                "{\"KHR_materials_emissive_strength\": {\"emissiveStrength\": 4}}},\n"
                "  {\"name\": \"glass\", \"pbrMetallicRoughness\": {\"metallicFactor\": 0, \"roughnessFactor\": 0.1}, "
                "\"extensions\": {\"KHR_materials_transmission\": {\"transmissionFactor\": 1}, "
                "\"KHR_materials_ior\": {\"ior\": 1.45}}}],\n");
    putf(&body, "\"meshes\": [{\"name\": \"torus\", \"primitives\": [{\"attributes\": {\"POSITION\": %d, "
                "\"NORMAL\": %d, \"TEXCOORD_0\": %d}, \"indices\": %d, \"material\": 0}]},\n",
         a.position, a.normal, a.uv, a.indices);
    putf(&body, "  {\"name\": \"panel\", \"primitives\": [\n"
                "    {\"attributes\": {\"POSITION\": %d}, \"indices\": %d, \"mode\": 5, \"material\": 2},\n"
                "    {\"attributes\": {\"POSITION\": %d, \"COLOR_0\": %d}, \"mode\": 6, \"material\": 1},\n"
                "    {\"attributes\": {\"POSITION\": %d}, \"mode\": 0}]}]",
         strip_position, strip_indices, fan_position, fan_color, point_position);
    put(&body, "", 1);
    write_gltf(name, &g, (const char *)body.data, kind, image);
    free(body.data);
    free_gltf(&g);
}

/* big.glb and big.ply: a torus of at least triangles triangles. */
static void write_big(long triangles)
{
    int tube = 64;
    int around = (int)((triangles + 2 * tube - 1) / (2 * tube));
    if (around < 3)
        around = 3;
    mesh m = torus(around, tube);
    gltf g = {0};
    torus_accessors a = add_torus(&g, &m);
    buffer body = {0};
    putf(&body, "\"scene\": 0, \"scenes\": [{\"nodes\": [0]}],\n\"nodes\": [{\"mesh\": 0}],\n"
                "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": %d, \"NORMAL\": %d, "
                "\"TEXCOORD_0\": %d}, \"indices\": %d}]}]",
         a.position, a.normal, a.uv, a.indices);
    put(&body, "", 1);
    write_gltf("big.glb", &g, (const char *)body.data, BINARY, NULL);
    free(body.data);
    free_gltf(&g);
    write_ply("big.ply", &m, PLY_LITTLE, 0);
    printf("big.glb, big.ply: %d triangles, %d vertices\n", 2 * m.quad_count, m.vertex_count);
    free_mesh(&m);
}

int main(int argc, char **argv)
{
    if (argc != 2 && !(argc == 4 && strcmp(argv[2], "big") == 0)) {
        fprintf(stderr, "usage: models DIR | models DIR big TRIANGLES\n");
        return 2;
    }
    output_directory = argv[1];
    if (mkdir(output_directory, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "models: cannot make %s: %s\n", output_directory, strerror(errno));
        return 1;
    }
    if (argc == 4) {
        write_big(atol(argv[3]));
        return 0;
    }
    mesh m = torus(TORUS_AROUND, TORUS_TUBE);
    write_obj("torus.obj", &m);
    write_ply("torus-ascii.ply", &m, PLY_ASCII, 1);
    write_ply("torus-le.ply", &m, PLY_LITTLE, 1);
    write_ply("torus-be.ply", &m, PLY_BIG, 1);
    buffer png = checker_png();
    write_file("checker.png", &png);
    write_torus_model("single.gltf", &m, 0);
    write_torus_model("pair.gltf", &m, 1);
    write_rich_model("model.gltf", &m, EXTERNAL, &png);
    write_rich_model("model-embedded.gltf", &m, DATA_URIS, &png);
    write_rich_model("model.glb", &m, BINARY, &png);
    printf("models: torus %d triangles, model %d triangles\n", 2 * m.quad_count, MODEL_TRIANGLES);
    free(png.data);
    free_mesh(&m);
    return 0;
}
