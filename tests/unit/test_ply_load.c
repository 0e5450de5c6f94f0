/* test_ply_load.c: the PLY reader (core/ply_load.c): ASCII and both binary byte orders
 * read the same mesh, polygons are fan-triangulated, what a mesh does not use is skipped
 * by its type, attributes by their names, and every refusal of ply_load.h with its
 * message; then `mesh "x.ply"` through scene_load_assets() (colours decoded from sRGB,
 * the mesh's material on every triangle, errors with the statement's position). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ply_load.h"
#include "scene.h"
#include "scene_assets.h"
#include "scene_parse.h"
#include "support.h"

const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "fast_unwind_on_malloc=0"; }

/* A square and a triangle: 5 vertices with normals (not unit), uvs and colours, faces of
 * 4 and 3 corners (3 triangles), an extra vertex property and an element to skip. */
static const char square_ascii[] =
    "ply\n"
    "format ascii 1.0\n"
    "comment a unit square and a triangle\n"
    "obj_info made by hand\n"
    "element vertex 5\n"
    "property float x\nproperty float y\nproperty float z\n"
    "property float nx\nproperty float ny\nproperty float nz\n"
    "property float s\nproperty float t\n"
    "property short quality\n"
    "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    "element face 2\n"
    "property list uchar int vertex_indices\n"
    "property uchar flags\n"
    "element material 1\n"
    "property list int double weights\n"
    "end_header\n"
    "0 0 0  0 0 2  0 0  -3  255 0 0\n"
    "1 0 0  0 0 2  1 0  7  0 255 0\n"
    "1 1 0  0 0 2  1 1  0  0 0 255\n"
    "0 1 0  0 0 2  0 1  1  128 128 128\n"
    "2 0 0  0 3 4  0.5 0.5  2  0 0 0\n"
    "4 0 1 2 3 9\n"
    "3 1 4 2 0\n"
    "2 0.5 0.25\n";

/* The same file in binary, big or little endian (what square_ascii says). */
static size_t square_binary(unsigned char *out, int big)
{
    static const float vertices[5][8] = {
        {0, 0, 0, 0, 0, 2, 0, 0}, {1, 0, 0, 0, 0, 2, 1, 0}, {1, 1, 0, 0, 0, 2, 1, 1},
        {0, 1, 0, 0, 0, 2, 0, 1}, {2, 0, 0, 0, 3, 4, 0.5f, 0.5f},
    };
    static const short quality[5] = {-3, 7, 0, 1, 2};
    static const unsigned char colours[5][3] = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {128, 128, 128}, {0, 0, 0}};
    /* The ASCII header with its format line changed. */
    const char *data = strstr(square_ascii, "end_header\n") + strlen("end_header\n");
    const char *format = strstr(square_ascii, "format ascii 1.0");
    const char *after_format = format + strlen("format ascii 1.0");
    size_t n = (size_t)sprintf((char *)out, "%.*sformat %s 1.0%.*s", (int)(format - square_ascii), square_ascii,
                               big ? "binary_big_endian" : "binary_little_endian", (int)(data - after_format),
                               after_format);
#define PUT(value, size)                                                   \
    do {                                                                   \
        unsigned char bytes[8];                                            \
        memcpy(bytes, &(value), size);                                     \
        for (int k = 0; k < (size); k++)                                   \
            out[n++] = bytes[big ? (size) - 1 - k : k];                    \
    } while (0)
    for (int v = 0; v < 5; v++) {
        for (int k = 0; k < 8; k++)
            PUT(vertices[v][k], 4);
        PUT(quality[v], 2);
        for (int k = 0; k < 3; k++)
            out[n++] = colours[v][k];
    }
    static const int square[4] = {0, 1, 2, 3}, triangle[3] = {1, 4, 2};
    out[n++] = 4;
    for (int k = 0; k < 4; k++)
        PUT(square[k], 4);
    out[n++] = 9;
    out[n++] = 3;
    for (int k = 0; k < 3; k++)
        PUT(triangle[k], 4);
    out[n++] = 0;
    int two = 2;
    double weights[2] = {0.5, 0.25};
    PUT(two, 4);
    PUT(weights[0], 8);
    PUT(weights[1], 8);
#undef PUT
    return n;
}

static ply_mesh load_ok(scratch *s, const char *name, const void *bytes, size_t size)
{
    ply_mesh mesh;
    rt_error error = {{0}};
    rt_status status = ply_load(scratch_write(s, name, bytes, size), &mesh, &error);
    if (status != RT_OK)
        print_error("%s\n", error.message);
    assert_int_equal(status, RT_OK);
    return mesh;
}

/* Loads text as a PLY file that must be refused; checks the contract and returns the
 * reason (after "PLY: cannot read 'PATH': "). */
static const char *refused(scratch *s, const char *text, rt_error *error)
{
    ply_mesh mesh;
    const char *path = write_file(s, "bad.ply", text);
    char prefix[600];
    snprintf(prefix, sizeof prefix, "PLY: cannot read '%s': ", path);
    assert_int_equal(ply_load(path, &mesh, error), RT_ERROR_INPUT);
    assert_null(mesh.positions);
    assert_null(mesh.indices);
    assert_int_equal(mesh.vertex_count, 0);
    assert_int_equal(strncmp(error->message, prefix, strlen(prefix)), 0);
    return error->message + strlen(prefix);
}

static void check_square(const ply_mesh *m)
{
    assert_int_equal(m->vertex_count, 5);
    assert_int_equal(m->triangle_count, 3);
    static const uint32_t expected[9] = {0, 1, 2, 0, 2, 3, 1, 4, 2};
    for (int i = 0; i < 9; i++)
        assert_int_equal(m->indices[i], expected[i]);
    assert_close(m->positions[3 * 4], 2, 0);
    assert_close(m->positions[3 * 2 + 1], 1, 0);
    /* Normals made unit length. */
    assert_close(m->normals[2], 1, 1e-7);
    assert_close(m->normals[3 * 4 + 1], 0.6, 1e-7);
    assert_close(m->normals[3 * 4 + 2], 0.8, 1e-7);
    assert_close(m->uvs[2 * 2], 1, 0);
    assert_close(m->uvs[2 * 4 + 1], 0.5, 0);
    /* Colours as encoded, an integer divided by its largest value. */
    assert_close(m->colors[0], 1, 0);
    assert_close(m->colors[3 * 3], 128.0 / 255.0, 1e-7);
    assert_close(m->colors[3 * 2 + 2], 1, 0);
}

static void test_ascii_and_binary_read_the_same_mesh(void **state)
{
    scratch *s = *state;
    ply_mesh ascii = load_ok(s, "a.ply", square_ascii, strlen(square_ascii));
    check_square(&ascii);
    for (int big = 0; big < 2; big++) {
        unsigned char bytes[4096];
        size_t size = square_binary(bytes, big);
        ply_mesh binary = load_ok(s, big ? "be.ply" : "le.ply", bytes, size);
        check_square(&binary);
        assert_memory_equal(binary.positions, ascii.positions, 15 * sizeof(float));
        assert_memory_equal(binary.normals, ascii.normals, 15 * sizeof(float));
        assert_memory_equal(binary.uvs, ascii.uvs, 10 * sizeof(float));
        assert_memory_equal(binary.colors, ascii.colors, 15 * sizeof(float));
        ply_mesh_free(&binary);
    }
    ply_mesh_free(&ascii);
}

static void test_polygons_are_fans_and_attributes_optional(void **state)
{
    scratch *s = *state;
    const char *text = "ply\r\nformat ascii 1.0\r\nelement vertex 5\r\nproperty double x\r\nproperty int y\r\n"
                       "property uchar z\r\nproperty float u\r\nproperty float v\r\nelement face 1\r\n"
                       "property list ushort uint vertex_index\r\nend_header\r\n"
                       "0 0 0 0 0\n1 0 0 1 0\n2 1 0 1 1\n1 2 0 0 1\n0 1 0 0.5 0.5\n5 0 1 2 3 4\n";
    ply_mesh m = load_ok(s, "fan.ply", text, strlen(text));
    assert_int_equal(m.triangle_count, 3);
    static const uint32_t fan[9] = {0, 1, 2, 0, 2, 3, 0, 3, 4};
    for (int i = 0; i < 9; i++)
        assert_int_equal(m.indices[i], fan[i]);
    assert_null(m.normals);
    assert_null(m.colors);
    assert_non_null(m.uvs);
    assert_close(m.uvs[2 * 2 + 1], 1, 0);
    ply_mesh_free(&m);

    /* texture_u / texture_v, float colours (clamped), no uvs. */
    text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
           "property float texture_u\nproperty float texture_v\nproperty float red\nproperty float green\n"
           "property float blue\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
           "0 0 0 0.25 0.75 0.5 2 -1\n1 0 0 0 0 0 0 0\n0 1 0 0 0 0 0 0\n3 0 1 2\n";
    m = load_ok(s, "names.ply", text, strlen(text));
    assert_close(m.uvs[0], 0.25, 0);
    assert_close(m.uvs[1], 0.75, 0);
    assert_close(m.colors[0], 0.5, 0);
    assert_close(m.colors[1], 1, 0);
    assert_close(m.colors[2], 0, 0);
    ply_mesh_free(&m);
}

static void test_header_refusals(void **state)
{
    scratch *s = *state;
    rt_error e;
    assert_string_equal(refused(s, "", &e), "line 1: not a PLY file (it is empty)");
    assert_string_equal(refused(s, "OFF\n3 1 0\n", &e), "line 1: not a PLY file (it does not start with a 'ply' line)");
    assert_string_equal(refused(s, "ply\nformat binary_middle_endian 1.0\nend_header\n", &e),
                        "line 2: unknown format 'binary_middle_endian' (expected ascii, binary_little_endian or "
                        "binary_big_endian)");
    assert_string_equal(refused(s, "ply\nformat ascii 2.0\nend_header\n", &e),
                        "line 2: unknown format version '2.0' (expected 1.0)");
    assert_string_equal(refused(s, "ply\nelement vertex 1\n", &e),
                        "line 2: expected 'format ascii 1.0' (or binary_little_endian, binary_big_endian) after the "
                        "'ply' line");
    assert_string_equal(refused(s, "ply\nformat ascii 1.0\nproperty float x\nend_header\n", &e),
                        "line 3: a property before any element");
    assert_string_equal(refused(s, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float16 x\nend_header\n", &e),
                        "line 4: unknown type 'float16' of property 'x'");
    assert_string_equal(refused(s, "ply\nformat ascii 1.0\nelement vertex -1\nend_header\n", &e),
                        "line 3: the count of element 'vertex' must be a whole number from 0 to 2147483647, found "
                        "'-1'");
    assert_string_equal(refused(s, "ply\nformat ascii 1.0\nelement vertex 1\nelement vertex 2\nend_header\n", &e),
                        "line 4: element 'vertex' is declared twice");
    assert_string_equal(refused(s, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", &e),
                        "the header has no end_header line");
    assert_string_equal(refused(s, "ply\nformat ascii 1.0\nvertices 3\nend_header\n", &e),
                        "line 3: unknown header line 'vertices' (expected element, property, comment, obj_info or "
                        "end_header)");
    assert_string_equal(refused(s, "ply\nformat ascii 1.0\nelement vertex 1\nproperty list float int x\n", &e),
                        "line 4: the count of list property 'x' has the float type 'float'");
}

/* The header of a vertex element with props, then a face element with faces. */
#define HEAD(props, faces) "ply\nformat ascii 1.0\nelement vertex 3\n" props "element face " faces "\n"
#define XYZ "property float x\nproperty float y\nproperty float z\n"
#define FACES "property list uchar int vertex_indices\n"

static void test_element_refusals(void **state)
{
    scratch *s = *state;
    rt_error e;
    assert_string_equal(refused(s, "ply\nformat ascii 1.0\nelement face 0\n" FACES "end_header\n", &e),
                        "the header declares no 'vertex' element");
    assert_string_equal(refused(s, "ply\nformat ascii 1.0\nelement vertex 1\n" XYZ "end_header\n0 0 0\n", &e),
                        "the header declares no 'face' element (a point cloud is not a mesh)");
    assert_string_equal(refused(s, HEAD("property float x\nproperty float y\n", "1") FACES "end_header\n", &e),
                        "the vertex element has no property 'z'");
    assert_string_equal(refused(s, HEAD(XYZ "property float nx\n", "1") FACES "end_header\n", &e),
                        "the vertex element has only some of nx, ny and nz (a normal needs all three)");
    assert_string_equal(refused(s, HEAD(XYZ "property uchar red\nproperty uchar blue\n", "1") FACES "end_header\n", &e),
                        "the vertex element has only some of red, green and blue (a colour needs all three)");
    assert_string_equal(refused(s, HEAD(XYZ "property float s\n", "1") FACES "end_header\n", &e),
                        "the vertex element has only one texture coordinate (s t, u v, texture_u texture_v or "
                        "texture_s texture_t come in pairs)");
    assert_string_equal(refused(s, HEAD(XYZ, "1") "property list uchar int corners\nend_header\n", &e),
                        "the face element has no 'vertex_indices' (or 'vertex_index') list");
    assert_string_equal(refused(s, HEAD(XYZ, "1") "property list uchar float vertex_indices\nend_header\n", &e),
                        "line 8: the face property 'vertex_indices' must be a list of whole numbers");
    assert_string_equal(refused(s, HEAD("property list uchar float x\nproperty float y\nproperty float z\n", "1")
                                       FACES "end_header\n", &e),
                        "line 4: the vertex property 'x' is a list; it must be one number");
}

static void test_data_refusals(void **state)
{
    scratch *s = *state;
    rt_error e;
    const char *head = HEAD(XYZ, "1") FACES "end_header\n";
    char text[1024];
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 abc 0\n3 0 1 2\n", head);
    assert_string_equal(refused(s, text, &e), "line 12: expected a number for 'y' of vertex 2, found 'abc'");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n", head);
    assert_string_equal(refused(s, text, &e), "line 13: the value 300 of 'vertex_indices' of face 0 does not fit its "
                                             "type uchar");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n2 0 1\n", head);
    assert_string_equal(refused(s, text, &e), "face 0 has 2 corners; a face needs at least 3");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", head);
    assert_string_equal(refused(s, text, &e), "face 0: vertex index 3 is out of range: the file has 3 vertices");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", head);
    assert_string_equal(refused(s, text, &e), "face 0: vertex index -1 is out of range: the file has 3 vertices");
    snprintf(text, sizeof text, "%s0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", head);
    assert_string_equal(refused(s, text, &e), "vertex 1: 'x' is not a finite number (NaN, infinite or beyond the "
                                             "range of a float)");
    snprintf(text, sizeof text, "%s0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n", head);
    assert_string_equal(refused(s, text, &e), "vertex 1: 'x' is not a finite number (NaN, infinite or beyond the "
                                             "range of a float)");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1 2\njunk\n", head);
    assert_string_equal(refused(s, text, &e), "line 14: 'junk' after the last element");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n3 0 1", head);
    assert_string_equal(refused(s, text, &e), "the data ends inside face 0 (the header declares 1)");
    snprintf(text, sizeof text, "%s0 0 0\n1 0 0\n0 1 0\n", HEAD(XYZ, "0") FACES "end_header\n");
    assert_string_equal(refused(s, text, &e), "the file has no faces");
    assert_string_equal(refused(s, "ply\nformat ascii 1.0\nelement vertex 2000000000\n" XYZ "element face 1\n" FACES
                                   "end_header\n0 0 0\n",
                                &e),
                        "the data is too short for the 2000000000 vertex records the header declares (6 bytes are "
                        "left, each record takes at least 6)");
    /* Binary: short data, and bytes after the last element. */
    const char *binary_head = "ply\nformat binary_little_endian 1.0\nelement vertex 3\n" XYZ "element face 1\n" FACES
                              "end_header\n";
    unsigned char bytes[512];
    size_t n = strlen(binary_head);
    memcpy(bytes, binary_head, n);
    float corners[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    memcpy(bytes + n, corners, sizeof corners);
    n += sizeof corners;
    int face[3] = {0, 1, 2};
    bytes[n++] = 3;
    memcpy(bytes + n, face, sizeof face);
    ply_mesh mesh;
    assert_int_equal(ply_load_memory(bytes, n + sizeof face, "x.ply", &mesh, &e), RT_OK);
    assert_int_equal(mesh.triangle_count, 1);
    ply_mesh_free(&mesh);
    assert_int_equal(ply_load_memory(bytes, n + sizeof face - 1, "x.ply", &mesh, &e), RT_ERROR_INPUT);
    assert_string_equal(e.message, "PLY: cannot read 'x.ply': the data ends inside face 0 (the header declares 1)");
    bytes[n + sizeof face] = 7;
    assert_int_equal(ply_load_memory(bytes, n + sizeof face + 1, "x.ply", &mesh, &e), RT_ERROR_INPUT);
    assert_string_equal(e.message, "PLY: cannot read 'x.ply': 1 bytes after the last element");
    assert_int_equal(ply_load_memory(bytes, strlen(binary_head) - strlen("end_header\n"), "x.ply", &mesh, &e), RT_ERROR_INPUT);
    assert_string_equal(e.message, "PLY: cannot read 'x.ply': the header has no end_header line");
}

static void test_missing_and_directory_files(void **state)
{
    scratch *s = *state;
    ply_mesh mesh;
    rt_error e;
    char path[600];
    snprintf(path, sizeof path, "%s", in_scratch(s, "none.ply"));
    assert_int_equal(ply_load(path, &mesh, &e), RT_ERROR_INPUT);
    assert_contains(e.message, "No such file or directory");
    assert_int_equal(ply_load(s->directory, &mesh, &e), RT_ERROR_INPUT);
    assert_contains(e.message, "': it is a directory");
}

/* A scene placing a PLY mesh (with colours) and an OBJ of the same two triangles. */
static void test_ply_meshes_in_a_scene(void **state)
{
    scratch *s = *state;
    write_file(s, "sq.ply", square_ascii);
    write_file(s, "sq.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nf 1 2 3 \nf 1 3 4\nf 2 5 3\n");
    const char *scene_path = write_file(s, "scene.txt",
                                        "material m lambertian 0.5 0.5 0.5\nmesh \"sq.ply\" m\nmesh \"sq.obj\" m\n"
                                        "mesh \"missing.ply\" m\n");
    scene sc;
    rt_error e;
    assert_int_equal(scene_load_file(scene_path, NULL, &sc, &e), RT_OK);
    assert_int_equal(scene_load_assets(&sc, &e), RT_ERROR_INPUT);
    assert_contains(e.message, "scene.txt:4:6: cannot read mesh '");
    assert_contains(e.message, "missing.ply': No such file or directory");
    const scene_mesh *ply = &sc.meshes[0], *obj = &sc.meshes[1];
    assert_int_equal(ply->triangle_count, 3);
    assert_int_equal(obj->triangle_count, 3);
    /* The same triangles, corner for corner. */
    for (int t = 0; t < 3; t++) {
        assert_int_equal(ply->triangle_materials[t], -1);
        for (int k = 0; k < 3; k++)
            assert_memory_equal(ply->positions + 3 * ply->indices[3 * t + k], obj->positions + 3 * obj->indices[3 * t + k],
                                3 * sizeof(float));
    }
    /* Colours decoded from sRGB: 128 is 0.2158. */
    assert_non_null(ply->colors);
    assert_close(ply->colors[3 * 3], 0.21586, 1e-4);
    assert_close(ply->colors[0], 1, 1e-6);
    assert_null(obj->colors);
    scene_free(&sc);

    /* A glTF file named by mesh is refused at the statement. */
    scene_path = write_file(s, "gltf.txt", "material m lambertian 0.5 0.5 0.5\nmesh \"model.glb\" m\n");
    assert_int_equal(scene_load_file(scene_path, NULL, &sc, &e), RT_ERROR_INPUT);
    assert_contains(e.message, "gltf.txt:2:6: a glTF file is a model, not a mesh: place it with the gltf statement");
}

int main(void)
{
#define T(name) cmocka_unit_test_setup_teardown(name, make_scratch, remove_scratch)
    const struct CMUnitTest tests[] = {
        T(test_ascii_and_binary_read_the_same_mesh),
        T(test_polygons_are_fans_and_attributes_optional),
        T(test_header_refusals),
        T(test_element_refusals),
        T(test_data_refusals),
        T(test_missing_and_directory_files),
        T(test_ply_meshes_in_a_scene),
    };
#undef T
    return cmocka_run_group_tests(tests, NULL, NULL);
}
