/* test_scene_assets.c: the asset loader. OBJ files through obj_load() (triangulation,
 * relative indices, vertex unification, what tinyobjloader refuses or reads leniently,
 * every error the validation of its arrays finds) and
 * scene_load_assets() (usemtl to scene materials, MTL-derived materials, images decoded
 * to linear RGBA, the sky box check, errors prefixed with the naming statement's
 * position). Each test writes its small files into its own mkdtemp directory. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image_io.h"
#include "obj_load.h"
#include "scene.h"
#include "scene_assets.h"
#include "support.h"

/* Under SAN=1 OpenImageIO needs the slow unwinder for its stacks (as in test_image_io). */
const char *__asan_default_options(void);
const char *__asan_default_options(void) { return "fast_unwind_on_malloc=0"; }

#define POSITION "scenes/x.txt:12:6"

/* Writes a width x height image of channels channels, every pixel = value (per channel). */
static void write_image(const char *path, int width, int height, int channels, const float *value)
{
    rt_image image;
    rt_error error;
    assert_int_equal(image_create(&image, width, height, channels, &error), RT_OK);
    for (size_t i = 0; i < (size_t)width * height; i++)
        for (int c = 0; c < channels; c++)
            image.pixels[i * channels + c] = value[c];
    if (channels == 2)
        strcpy(image.channel_names[1], "A");
    rt_status status = image_write(path, &image, NULL, &error);
    if (status != RT_OK)
        print_error("%s\n", error.message);
    assert_int_equal(status, RT_OK);
    image_free(&image);
}

/* ---- helpers for meshes --------------------------------------------------------------- */

static obj_mesh load_ok(scratch *s, const char *name, const char *text)
{
    obj_mesh mesh;
    rt_error error = {{0}};
    rt_status status = obj_load(write_file(s, name, text), &mesh, &error);
    if (status != RT_OK)
        print_error("%s\n", error.message);
    assert_int_equal(status, RT_OK);
    return mesh;
}

/* Loads text as an OBJ that must fail with RT_ERROR_INPUT; returns the message. */
static const char *load_fails(scratch *s, const char *name, const char *text, rt_error *error)
{
    obj_mesh mesh;
    const char *path = write_file(s, name, text);
    assert_int_equal(obj_load(path, &mesh, error), RT_ERROR_INPUT);
    assert_null(mesh.positions);
    assert_null(mesh.indices);
    assert_int_equal(mesh.triangle_count, 0);
    assert_contains(error->message, "OBJ: cannot read '");
    assert_contains(error->message, name);
    return error->message;
}

/* load_fails(), then checks that the message contains expected. */
static void load_fails_saying(scratch *s, const char *name, const char *text, const char *expected)
{
    rt_error error;
    assert_contains(load_fails(s, name, text, &error), expected);
}

static const float *vertex_of(const obj_mesh *mesh, int triangle, int corner)
{
    return &mesh->positions[3 * mesh->indices[3 * triangle + corner]];
}

/* The triangle's normal vector (cross product): twice its area, pointing to the front. */
static void triangle_cross(const obj_mesh *mesh, int t, double out[3])
{
    const float *a = vertex_of(mesh, t, 0), *b = vertex_of(mesh, t, 1), *c = vertex_of(mesh, t, 2);
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    out[0] = e1[1] * e2[2] - e1[2] * e2[1];
    out[1] = e1[2] * e2[0] - e1[0] * e2[2];
    out[2] = e1[0] * e2[1] - e1[1] * e2[0];
}

/* Asserts every triangle of a mesh in the z = 0 plane faces +z and that their areas sum
 * to area (the polygon is covered exactly, with no overlap or gap, when it is convex or
 * when the triangulation respects a concave outline). Also checks indices are in range. */
static void assert_covers(const obj_mesh *mesh, double area)
{
    double total = 0;
    for (int t = 0; t < mesh->triangle_count; t++) {
        for (int k = 0; k < 3; k++)
            assert_true(mesh->indices[3 * t + k] < (uint32_t)mesh->vertex_count);
        double n[3];
        triangle_cross(mesh, t, n);
        assert_close(n[0], 0, 1e-6);
        assert_close(n[1], 0, 1e-6);
        assert_true(n[2] > 0);
        total += n[2] / 2;
    }
    assert_close(total, area, 1e-5);
}

/* ---- obj_load: geometry ---------------------------------------------------------------- */

static void test_quad_becomes_two_triangles(void **state)
{
    obj_mesh mesh = load_ok(*state, "quad.obj",
                            "# a unit square\n"
                            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                            "f 1 2 3 4\n");
    assert_int_equal(mesh.triangle_count, 2);
    assert_int_equal(mesh.vertex_count, 4);
    assert_null(mesh.normals);
    assert_null(mesh.uvs);
    assert_int_equal(mesh.material_count, 0);
    assert_int_equal(mesh.triangle_materials[0], -1);
    assert_int_equal(mesh.triangle_materials[1], -1);
    assert_int_equal(mesh.warning_count, 0);
    assert_covers(&mesh, 1.0);
    /* all four corners are used */
    bool used[4] = {false};
    for (int i = 0; i < 6; i++)
        used[mesh.indices[i]] = true;
    assert_true(used[0] && used[1] && used[2] && used[3]);
    obj_mesh_free(&mesh);
    assert_null(mesh.positions);
}

static void test_ngons_are_triangulated(void **state)
{
    /* a regular hexagon of circumradius 1 and a concave L of area 3 */
    obj_mesh hexagon = load_ok(*state, "hexagon.obj",
                               "v 1 0 0\nv 0.5 0.8660254 0\nv -0.5 0.8660254 0\n"
                               "v -1 0 0\nv -0.5 -0.8660254 0\nv 0.5 -0.8660254 0\n"
                               "f 1 2 3 4 5 6\n");
    assert_int_equal(hexagon.triangle_count, 4);
    assert_int_equal(hexagon.vertex_count, 6);
    assert_covers(&hexagon, 3 * 0.8660254);
    obj_mesh_free(&hexagon);

    obj_mesh ell = load_ok(*state, "ell.obj",
                           "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n"
                           "f 1 2 3 4 5 6\n");
    assert_int_equal(ell.triangle_count, 4);
    assert_covers(&ell, 3.0);
    obj_mesh_free(&ell);
}

static void test_negative_indices(void **state)
{
    /* relative indices count back from the line: the vertex after the face is not seen */
    obj_mesh mesh = load_ok(*state, "relative.obj",
                            "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                            "vt 0.25 0.5\nvn 0 0 1\n"
                            "f -3/-1/-1 -2/-1/-1 -1/-1/-1\n"
                            "v 5 5 5\n"
                            "f 1/1/1 2/1/1 -1/1/1\n");
    assert_int_equal(mesh.triangle_count, 2);
    assert_int_equal(mesh.vertex_count, 4);
    const float expected[2][3][3] = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {1, 0, 0}, {5, 5, 5}}};
    for (int t = 0; t < 2; t++)
        for (int k = 0; k < 3; k++)
            for (int c = 0; c < 3; c++)
                assert_close(vertex_of(&mesh, t, k)[c], expected[t][k][c], 0);
    assert_non_null(mesh.uvs);
    assert_close(mesh.uvs[0], 0.25, 0);
    assert_close(mesh.uvs[1], 0.5, 0);
    obj_mesh_free(&mesh);
}

static void test_missing_normals_and_uvs(void **state)
{
    obj_mesh plain = load_ok(*state, "plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_null(plain.normals);
    assert_null(plain.uvs);
    assert_int_equal(plain.vertex_count, 3);
    obj_mesh_free(&plain);

    obj_mesh uv_only = load_ok(*state, "uv.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n");
    assert_null(uv_only.normals);
    assert_non_null(uv_only.uvs);
    obj_mesh_free(&uv_only);

    obj_mesh normal_only = load_ok(*state, "n.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 2\nf 1//1 2//1 3//1\n");
    assert_non_null(normal_only.normals);
    assert_null(normal_only.uvs);
    for (int v = 0; v < normal_only.vertex_count; v++)  /* made unit length */
        assert_close(normal_only.normals[3 * v + 2], 1.0, 1e-6);
    obj_mesh_free(&normal_only);
}

/* The file's corners (position, uv, normal indices, 1-based) for the unification test. */
static const float unify_positions[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
static const float unify_uvs[3][2] = {{0.1f, 0.2f}, {0.3f, 0.4f}, {0.5f, 0.6f}};
static const float unify_normals[2][3] = {{0, 0, 1}, {0, 1, 0}};
static const int unify_faces[4][3][3] = {
    {{1, 1, 1}, {2, 2, 1}, {3, 3, 1}},  /* 3 new vertices */
    {{1, 1, 1}, {3, 3, 1}, {4, 1, 1}},  /* shares (1,1,1) and (3,3,1): 1 new */
    {{1, 1, 2}, {2, 2, 2}, {4, 3, 2}},  /* same positions, other normal: 3 new */
    {{2, 3, 1}, {3, 3, 1}, {4, 1, 1}},  /* (2,3,1) is new (other uv), the rest shared */
};

static void test_vertices_unify_position_normal_uv(void **state)
{
    obj_mesh mesh = load_ok(*state, "unify.obj",
                            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                            "vt 0.1 0.2\nvt 0.3 0.4\nvt 0.5 0.6\n"
                            "vn 0 0 1\nvn 0 1 0\n"
                            "f 1/1/1 2/2/1 3/3/1\n"
                            "f 1/1/1 3/3/1 4/1/1\n"
                            "f 1/1/2 2/2/2 4/3/2\n"
                            "f 2/3/1 3/3/1 4/1/1\n");
    assert_int_equal(mesh.triangle_count, 4);
    assert_int_equal(mesh.vertex_count, 8);
    assert_non_null(mesh.normals);
    assert_non_null(mesh.uvs);
    for (int t = 0; t < 4; t++)
        for (int k = 0; k < 3; k++) {
            uint32_t v = mesh.indices[3 * t + k];
            assert_true(v < (uint32_t)mesh.vertex_count);
            const int *corner = unify_faces[t][k];
            for (int c = 0; c < 3; c++) {
                assert_close(mesh.positions[3 * v + c], unify_positions[corner[0] - 1][c], 0);
                assert_close(mesh.normals[3 * v + c], unify_normals[corner[2] - 1][c], 0);
            }
            for (int c = 0; c < 2; c++)
                assert_close(mesh.uvs[2 * v + c], unify_uvs[corner[1] - 1][c], 0);
        }
    /* distinct vertices are distinct triples: no two vertices are equal */
    for (int a = 0; a < mesh.vertex_count; a++)
        for (int b = a + 1; b < mesh.vertex_count; b++) {
            bool same = memcmp(&mesh.positions[3 * a], &mesh.positions[3 * b], 3 * sizeof(float)) == 0
                        && memcmp(&mesh.normals[3 * a], &mesh.normals[3 * b], 3 * sizeof(float)) == 0
                        && memcmp(&mesh.uvs[2 * a], &mesh.uvs[2 * b], 2 * sizeof(float)) == 0;
            assert_false(same);
        }
    obj_mesh_free(&mesh);
}

static void test_partly_missing_normals_get_the_face_normal(void **state)
{
    obj_mesh mesh = load_ok(*state, "partly.obj",
                            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 1 0 0\n"
                            "f 1//1 2//1 3//1\n"
                            "f 1 3 4\n");
    assert_int_equal(mesh.triangle_count, 2);
    assert_int_equal(mesh.vertex_count, 6);
    for (int k = 0; k < 3; k++) {
        const float *first = &mesh.normals[3 * mesh.indices[k]];
        const float *second = &mesh.normals[3 * mesh.indices[3 + k]];
        assert_close(first[0], 1, 0);
        assert_close(second[0], 0, 1e-6);
        assert_close(second[2], 1, 1e-6);
    }
    obj_mesh_free(&mesh);
}

/* Found by fuzz_obj_load: near the float range a float cross product of the edges (and
 * the squared length of a file normal) overflowed, and the normal came back inf or NaN. */
static void test_normals_stay_unit_near_the_float_range(void **state)
{
    obj_mesh mesh = load_ok(*state, "huge.obj",
                            "v -1e38 0 0\nv 1e38 0 0\nv 0 3e38 0\nv 0 0 0\n"
                            "vn 2e38 2e38 0\nvn 1e-40 0 0\n"
                            "f 1 2 3\n"
                            "f 1//1 2//2 4//1\n");
    assert_int_equal(mesh.triangle_count, 2);
    for (int corner = 0; corner < 6; corner++) {
        const float *n = &mesh.normals[3 * mesh.indices[corner]];
        assert_close(sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1, 1e-5);
    }
    /* The first triangle's face normal is +z; the file's normals keep their directions. */
    assert_close(mesh.normals[3 * mesh.indices[0] + 2], 1, 1e-6);
    assert_close(mesh.normals[3 * mesh.indices[3] + 0], sqrtf(0.5f), 1e-6);
    assert_close(mesh.normals[3 * mesh.indices[4] + 0], 1, 1e-6);
    obj_mesh_free(&mesh);
}

static void test_crlf_bom_comments_and_groups(void **state)
{
    obj_mesh mesh = load_ok(*state, "windows.obj",
                            "\xEF\xBB\xBFv 0 0 0\r\nv 1 0 0\r\n# comment\r\n\r\n"
                            "o thing\r\ng part\r\ns 1\r\nv 0 1 0\r\n  f 1 2 3\r\n");
    assert_int_equal(mesh.triangle_count, 1);
    assert_int_equal(mesh.vertex_count, 3);
    obj_mesh_free(&mesh);

    /* line numbers (tinyobjloader's) count CRLF, CR and LF line endings alike */
    load_fails_saying(*state, "windows-bad.obj", "v 0 0 0\r\nv 1 0 0\rv 0 1 0\r\nf 1 2 0\r\n",
                      "zero value for face index. line 4.");
}

/* ---- obj_load: errors ---------------------------------------------------------------- */

/* Faces tinyobjloader cannot read stop it, in its words with the file's line number. */
static void test_malformed_lines(void **state)
{
    rt_error error;
    load_fails_saying(*state, "c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n",
                      "': tinyobjloader: Failed parse `f' line(e.g. zero value for face index. line 4.)");

    load_fails_saying(*state, "d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
                      "': tinyobjloader: Failed parse `f' line(e.g. zero value for face index. line 4.)");

    load_fails_saying(*state, "f.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x3\n",
                      "zero value for face index. line 4.");

    load_fails_saying(*state, "g.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ 2/ 3/\n",
                      "zero value for face index. line 4.");

    load_fails(*state, "h.obj", "v 0 0 0\nv 1 0 0\nl 0 1\nv 0 1 0\nf 1 2 3\n", &error);
    assert_contains(error.message, "tinyobjloader: Failed parse `l' line");
    assert_contains(error.message, "line 3");

    /* a face of two corners: tinyobjloader drops it with a warning; with no other face
     * the file has none */
    load_fails_saying(*state, "b.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
                      "': has no faces (tinyobjloader made no triangles; it warned: Degenerated face found)");
    obj_mesh mesh = load_ok(*state, "b2.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\nf 1 2 3\n");
    assert_int_equal(mesh.triangle_count, 1);
    assert_int_equal(mesh.warning_count, 1);
    assert_string_equal(mesh.warnings[0], "tinyobjloader: Degenerated face found");
    obj_mesh_free(&mesh);

    const char binary[] = "v 0 0 0\nv 1\0 0 0\n";
    const char *path = in_scratch(*state, "binary.obj");
    FILE *file = fopen(path, "wb");
    assert_non_null(file);
    fwrite(binary, 1, sizeof binary - 1, file);
    fclose(file);
    assert_int_equal(obj_load(path, &mesh, &error), RT_ERROR_INPUT);
    assert_contains(error.message, "line 2: a NUL byte");
}

/* What tinyobjloader reads leniently is read as it reads it (obj_load.h): a number it
 * cannot read is 0, a missing one is 0. */
static void test_tinyobjloader_reads_leniently(void **state)
{
    obj_mesh mesh = load_ok(*state, "lenient.obj",
                            "v 0 0 0\nv 1 abc 0\nv nan 1 0\n"
                            "vn -inf 0 1\nvn 0 1\n"
                            "vt NaN 0.5\n"
                            "f 1/1/1 2/1/1 3/1/2\n");
    assert_int_equal(mesh.triangle_count, 1);
    assert_int_equal(mesh.vertex_count, 3);
    const float expected[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    for (int k = 0; k < 3; k++)
        for (int c = 0; c < 3; c++)
            assert_close(vertex_of(&mesh, 0, k)[c], expected[k][c], 0);
    const float *n0 = &mesh.normals[3 * mesh.indices[0]], *n2 = &mesh.normals[3 * mesh.indices[2]];
    assert_close(n0[0], 0, 0);  /* (-inf, 0, 1) read as (0, 0, 1) */
    assert_close(n0[2], 1, 0);
    assert_close(n2[1], 1, 0);  /* (0, 1) read as (0, 1, 0) */
    assert_close(mesh.uvs[2 * mesh.indices[0]], 0, 0);
    assert_close(mesh.uvs[2 * mesh.indices[0] + 1], 0.5, 0);
    obj_mesh_free(&mesh);
}

static void test_out_of_range_indices(void **state)
{
    rt_error error;
    /* tinyobjloader keeps no line numbers in its arrays: the triangle is named, counted
     * in file order */
    load_fails_saying(*state, "a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n",
                      "': triangle 2: vertex index 9 is out of range: the file has 3 vertices");

    load_fails_saying(*state, "b.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n",
                      "': triangle 1: a relative vertex index points before the first vertex");

    load_fails_saying(*state, "c.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n",
                      "': triangle 1: normal index 2 is out of range: the file has 1 normals");

    load_fails_saying(*state, "d.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n",
                      "': triangle 1: texture coordinate index 1 is out of range: the file has 0 texture coordinates");

    load_fails(*state, "e.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999\n", &error);
    assert_contains(error.message, "': triangle 1: vertex index ");
    assert_contains(error.message, "out of range");

    /* an n-gon with an index past the end: tinyobjloader triangulates it as it is */
    load_fails_saying(*state, "g.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 1 7\n",
                      "': triangle 1: vertex index 7 is out of range");
    /* a quad with one: tinyobjloader drops it with a warning */
    load_fails(*state, "f.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\n", &error);
    assert_contains(error.message, "': has no faces (tinyobjloader made no triangles; it warned: ");
    assert_contains(error.message, "Face with invalid vertex index found.)");
    obj_mesh mesh = load_ok(*state, "f2.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 4\nf 1 2 3\n");
    assert_int_equal(mesh.triangle_count, 1);
    assert_int_equal(mesh.warning_count, 2);
    assert_string_equal(mesh.warnings[0], "tinyobjloader: Vertex indices out of bounds (line 5.)");
    assert_string_equal(mesh.warnings[1], "tinyobjloader: Face with invalid vertex index found.");
    obj_mesh_free(&mesh);
}

static void test_empty_files_have_no_faces(void **state)
{
    load_fails_saying(*state, "empty.obj", "", "': has no faces");
    load_fails_saying(*state, "points.obj", "# only vertices\nv 0 0 0\nv 1 0 0\nv 0 1 0\n",
                      "': has no faces");
    load_fails_saying(*state, "lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n", "': has no faces");
}

static void test_non_finite_numbers(void **state)
{
    /* tinyobjloader reads "nan" and "inf" as 0 (test_tinyobjloader_reads_leniently), but
     * numbers beyond the float range as infinities */
    load_fails_saying(*state, "big.obj", "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n",
                      "big.obj': vertex 2 has a coordinate that is not a finite number (beyond the range of a float)");
    load_fails_saying(*state, "bign.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 -1e39 1\nf 1//1 2//1 3//1\n",
                      "bign.obj': normal 2 has a coordinate that is not a finite number");
    load_fails_saying(*state, "bigt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 -1e40\nf 1/1 2/1 3/1\n",
                      "bigt.obj': texture coordinate 1 has a coordinate that is not a finite number");
}

static void test_missing_and_directory_files(void **state)
{
    scratch *s = *state;
    obj_mesh mesh;
    rt_error error;
    assert_int_equal(obj_load(in_scratch(s, "nothere.obj"), &mesh, &error), RT_ERROR_INPUT);
    assert_contains(error.message, "nothere.obj': No such file or directory");
    assert_int_equal(mkdir(in_scratch(s, "dir.obj"), 0755), 0);
    assert_int_equal(obj_load(s->path, &mesh, &error), RT_ERROR_INPUT);
    assert_contains(error.message, "dir.obj': it is a directory");
}

/* ---- materials ------------------------------------------------------------------------ */

/* Adds a mesh naming path (recorded at POSITION) to s; returns its index. */
static int add_mesh(scene *s, const char *path, int default_material)
{
    scene_mesh mesh;
    memset(&mesh, 0, sizeof mesh);
    snprintf(mesh.path, sizeof mesh.path, "%s", path);
    snprintf(mesh.position, sizeof mesh.position, "%s", POSITION);
    mesh.default_material = default_material;
    int index = scene_add_mesh(s, &mesh);
    assert_true(index >= 0);
    return index;
}

static int add_material(scene *s, const char *name, int type, float r, float g, float b)
{
    scene_material m = scene_material_defaults();
    snprintf(m.name, sizeof m.name, "%s", name);
    m.type = type;
    m.albedo[0] = r, m.albedo[1] = g, m.albedo[2] = b;
    int index = scene_add_material(s, &m);
    assert_true(index >= 0);
    return index;
}

static void load_scene_ok(scene *s)
{
    rt_error error = {{0}};
    rt_status status = scene_load_assets(s, &error);
    if (status != RT_OK)
        print_error("%s\n", error.message);
    assert_int_equal(status, RT_OK);
}


static void test_missing_mtl_still_loads(void **state)
{
    obj_mesh mesh = load_ok(*state, "nomtl.obj",
                            "mtllib nothere.mtl\n"
                            "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                            "f 1 2 3\nusemtl red\nf 1 2 3\n");
    assert_int_equal(mesh.triangle_count, 2);
    assert_int_equal(mesh.warning_count, 2);
    assert_contains(mesh.warnings[0], "cannot read material library '");
    assert_contains(mesh.warnings[0], "nothere.mtl': No such file or directory; its materials are left out");
    assert_string_equal(mesh.warnings[1], "tinyobjloader: Failed to load material file(s). Use default material.");
    assert_int_equal(mesh.material_count, 1);
    assert_string_equal(mesh.materials[0].name, "red");
    assert_false(mesh.materials[0].defined);
    assert_int_equal(mesh.triangle_materials[0], -1);
    assert_int_equal(mesh.triangle_materials[1], 0);
    obj_mesh_free(&mesh);
}

static void test_missing_mtl_in_a_scene(void **state)
{
    scratch *s = *state;
    const char *path = write_file(s, "lost.obj",
                                  "mtllib lost.mtl\n"
                                  "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                  "usemtl red\nf 1 2 3\nusemtl green\nf 1 2 3\n");
    scene sc;
    scene_defaults(&sc);
    int red = add_material(&sc, "red", MATERIAL_LAMBERTIAN, 1, 0, 0);
    add_mesh(&sc, path, -1);
    load_scene_ok(&sc);
    assert_int_equal(sc.material_count, 1);
    assert_int_equal(sc.meshes[0].triangle_count, 2);
    assert_int_equal(sc.meshes[0].triangle_materials[0], red);  /* the scene's, by name */
    assert_int_equal(sc.meshes[0].triangle_materials[1], -1);   /* no such material anywhere */
    /* The warnings are the scene's, for the caller to show, prefixed like an error. */
    assert_int_equal(sc.warning_count, 2);
    char expected[2048];
    snprintf(expected, sizeof expected, POSITION ": mesh '%s': cannot read material library '%s/lost.mtl': No such "
             "file or directory; its materials are left out", path, s->directory);
    assert_string_equal(sc.warnings[0].message, expected);
    snprintf(expected, sizeof expected, POSITION ": mesh '%s': tinyobjloader: Failed to load material file(s). Use "
             "default material.", path);
    assert_string_equal(sc.warnings[1].message, expected);
    /* A second call loads nothing again, so it warns nothing again. */
    load_scene_ok(&sc);
    assert_int_equal(sc.warning_count, 2);
    scene_free(&sc);
    assert_int_equal(sc.warning_count, 0);
    assert_null(sc.warnings);
}

/* tinyobjloader's own warnings are kept too, with the OBJ file's line numbers, and an MTL
 * file's name its file; past OBJ_MAX_WARNINGS they are counted. */
static void test_tinyobjloader_warnings_are_kept(void **state)
{
    scratch *s = *state;
    write_file(s, "both.mtl", "newmtl glass\nKd 1 1 1\nd 0.5\nTr 0.2\n");
    obj_mesh mesh = load_ok(s, "warn.obj",
                            "mtllib both.mtl\n"
                            "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                            "g \n"
                            "usemtl glass\nf 1 2 3\n");
    assert_int_equal(mesh.warning_count, 2);
    char expected[2048];
    snprintf(expected, sizeof expected, "tinyobjloader, in '%s/both.mtl': Both `d` and `Tr` parameters defined for "
             "\"glass\"", s->directory);
    assert_contains(mesh.warnings[0], expected);
    assert_contains(mesh.warnings[0], "(line 4 in .mtl");
    assert_string_equal(mesh.warnings[1], "tinyobjloader: Empty group name. line: 5");
    obj_mesh_free(&mesh);
    assert_int_equal(mesh.warning_count, 0);

    /* Ten missing MTL files and tinyobjloader's own warning that none loaded: eight
     * warnings kept, eleven counted; the scene says so. */
    const char *path = write_file(s, "many.obj",
                                  "mtllib a0.mtl a1.mtl a2.mtl a3.mtl a4.mtl a5.mtl a6.mtl a7.mtl a8.mtl a9.mtl\n"
                                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    mesh = load_ok(s, "many.obj",
                   "mtllib a0.mtl a1.mtl a2.mtl a3.mtl a4.mtl a5.mtl a6.mtl a7.mtl a8.mtl a9.mtl\n"
                   "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_int_equal(mesh.warning_count, 11);
    assert_contains(mesh.warnings[OBJ_MAX_WARNINGS - 1], "a7.mtl'");
    obj_mesh_free(&mesh);
    scene sc;
    scene_defaults(&sc);
    add_mesh(&sc, path, -1);
    load_scene_ok(&sc);
    assert_int_equal(sc.warning_count, OBJ_MAX_WARNINGS + 1);
    assert_contains(sc.warnings[0].message, "a0.mtl'");
    snprintf(expected, sizeof expected, POSITION ": mesh '%s': 3 more warnings left out", path);
    assert_string_equal(sc.warnings[OBJ_MAX_WARNINGS].message, expected);
    scene_free(&sc);
}

/* A usemtl name no MTL file defines where it is used is kept as a material (defined =
 * false) and not warned about; tinyobjloader's other warnings keep the file's line
 * numbers, and an MTL definition counts from its mtllib line on. */
static void test_usemtl_names_without_a_definition_are_kept(void **state)
{
    scratch *s = *state;
    write_file(s, "late.mtl", "newmtl blue\nKd 0 0 0.9\n");
    obj_mesh mesh = load_ok(s, "late.obj",
                            "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                            "usemtl blue\nf 1 2 3\n"
                            "usemtl red\nf 1 2 3\n"
                            "mtllib late.mtl\n"
                            "g \n"
                            "usemtl blue\nf 1 2 3\n");
    assert_int_equal(mesh.triangle_count, 3);
    assert_int_equal(mesh.warning_count, 1);
    assert_string_equal(mesh.warnings[0], "tinyobjloader: Empty group name. line: 9");
    const obj_material *first = &mesh.materials[mesh.triangle_materials[0]];
    const obj_material *second = &mesh.materials[mesh.triangle_materials[1]];
    const obj_material *third = &mesh.materials[mesh.triangle_materials[2]];
    assert_string_equal(first->name, "blue");
    assert_false(first->defined);
    assert_string_equal(second->name, "red");
    assert_false(second->defined);
    assert_string_equal(third->name, "blue");
    assert_true(third->defined);
    assert_close(third->diffuse[2], 0.9, 1e-6);
    obj_mesh_free(&mesh);
}

/* A volume's boundary must be closed: a mesh of fewer than 4 triangles cannot be. */
static void test_volume_mesh_too_small_to_close(void **state)
{
    scratch *s = *state;
    static const char *const meshes[2] = {
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
        /* a tetrahedron: the smallest closed mesh */
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    };
    for (int closed = 0; closed < 2; closed++) {
        const char *path = write_file(s, closed ? "tetrahedron.obj" : "one.obj", meshes[closed]);
        scene sc;
        scene_defaults(&sc);
        int mesh = add_mesh(&sc, path, -1);
        scene_object object = {.first_shape = 0, .shape_count = 0, .mesh = mesh};
        scene_instance instance = {.object = scene_add_object(&sc, &object), .material = -1, .volume = true,
                                   .density = 1, .volume_albedo = {1, 1, 1}};
        scene_identity_transform(instance.object_to_world);
        assert_true(scene_add_instance(&sc, &instance) >= 0);
        rt_error error = {{0}};
        rt_status status = scene_load_assets(&sc, &error);
        if (closed) {
            assert_int_equal(status, RT_OK);
        } else {
            assert_int_equal(status, RT_ERROR_INPUT);
            char expected[2048];
            snprintf(expected, sizeof expected, POSITION ": mesh '%s' is (part of) a volume's boundary, which must "
                     "be closed, but it has only 1 triangle: fewer than 4 enclose nothing", path);
            assert_string_equal(error.message, expected);
        }
        /* The same mesh placed as a surface is fine. */
        sc.instances[0].volume = false;
        load_scene_ok(&sc);
        scene_free(&sc);
    }
}

static void test_usemtl_names_scene_materials(void **state)
{
    scratch *s = *state;
    write_file(s, "m.mtl", "newmtl blue\nKd 0 0 0.9\n");
    const char *path = write_file(s, "named.obj",
                                  "mtllib m.mtl\n"
                                  "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                                  "f 1 2 3\n"
                                  "usemtl red\nf 1 2 3\n"
                                  "usemtl blue\nf 1 2 3\n"
                                  "usemtl nobody\nf 1 2 3\n");
    scene sc;
    scene_defaults(&sc);
    int red = add_material(&sc, "red", MATERIAL_LAMBERTIAN, 1, 0, 0);
    int blue = add_material(&sc, "blue", MATERIAL_METAL, 0, 0, 1);
    int fallback = add_material(&sc, "fallback", MATERIAL_LAMBERTIAN, 0.5f, 0.5f, 0.5f);
    int first = add_mesh(&sc, path, -1);
    int second = add_mesh(&sc, path, fallback);
    load_scene_ok(&sc);
    /* the scene's "blue" wins over the MTL's; no material was added */
    assert_int_equal(sc.material_count, 3);
    const scene_mesh *m = &sc.meshes[first];
    assert_int_equal(m->triangle_count, 4);
    assert_int_equal(m->vertex_count, 3);
    assert_non_null(m->positions);
    assert_non_null(m->indices);
    assert_int_equal(m->triangle_materials[0], -1);
    assert_int_equal(m->triangle_materials[1], red);
    assert_int_equal(m->triangle_materials[2], blue);
    assert_int_equal(m->triangle_materials[3], -1);
    m = &sc.meshes[second];
    assert_int_equal(m->triangle_materials[0], fallback);
    assert_int_equal(m->triangle_materials[1], red);
    assert_int_equal(m->triangle_materials[2], blue);
    assert_int_equal(m->triangle_materials[3], fallback);
    scene_free(&sc);
}

static void test_mtl_materials_become_scene_materials(void **state)
{
    scratch *s = *state;
    assert_int_equal(mkdir(in_scratch(s, "materials"), 0755), 0);
    write_file(s, "materials/set.mtl",
               "# five kinds\n"
               "newmtl clay\nKd 0.8 0.2 0.1\nKs 0.5 0.5 0.5\n"
               "newmtl lamp\nKd 1 1 1\nKe 4 3 2\n"
               "newmtl glass\nKd 1 1 1\nd 0.1\nNi 1.45\n"
               "newmtl water\nTr 0.5\n"
               "newmtl chrome\nKd 0.02 0.02 0.02\nKs 0.9 0.8 0.7\nNs 1000\n"
               "newmtl unused\nKd 0 1 0\n");
    const char *obj = "mtllib materials/set.mtl\n"
                      "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                      "usemtl clay\nf 1 2 3\nf 1 2 3\n"
                      "usemtl lamp\nf 1 2 3\n"
                      "usemtl glass\nf 1 2 3\n"
                      "usemtl water\nf 1 2 3\n"
                      "usemtl chrome\nf 1 2 3\n"
                      "usemtl clay\nf 1 2 3\n";
    char first_path[512], second_path[512];
    snprintf(first_path, sizeof first_path, "%s", write_file(s, "chair.obj", obj));
    snprintf(second_path, sizeof second_path, "%s", write_file(s, "table.obj", obj));
    scene sc;
    scene_defaults(&sc);
    add_material(&sc, "ground", MATERIAL_LAMBERTIAN, 0.5f, 0.5f, 0.5f);
    add_mesh(&sc, first_path, -1);
    add_mesh(&sc, second_path, -1);
    load_scene_ok(&sc);
    /* once per (mesh, MTL name) that a face uses: 5 + 5, none for "unused" */
    assert_int_equal(sc.material_count, 1 + 5 + 5);
    const int *tm = sc.meshes[0].triangle_materials;
    assert_int_equal(tm[0], tm[1]);
    assert_int_equal(tm[0], tm[6]);
    const scene_material *clay = &sc.materials[tm[0]];
    assert_string_equal(clay->name, "chair.obj:clay");
    assert_int_equal(clay->type, MATERIAL_LAMBERTIAN);
    assert_close(clay->albedo[0], 0.8, 1e-6);
    assert_close(clay->albedo[1], 0.2, 1e-6);
    assert_close(clay->albedo[2], 0.1, 1e-6);
    assert_int_equal(clay->albedo_texture, -1);
    const scene_material *lamp = &sc.materials[tm[2]];
    assert_string_equal(lamp->name, "chair.obj:lamp");
    assert_int_equal(lamp->type, MATERIAL_EMISSIVE);
    assert_close(lamp->emission[0], 4, 0);
    assert_close(lamp->emission[1], 3, 0);
    assert_close(lamp->emission[2], 2, 0);
    const scene_material *glass = &sc.materials[tm[3]];
    assert_string_equal(glass->name, "chair.obj:glass");
    assert_int_equal(glass->type, MATERIAL_DIELECTRIC);
    assert_close(glass->index_of_refraction, 1.45, 1e-6);
    const scene_material *water = &sc.materials[tm[4]];
    assert_int_equal(water->type, MATERIAL_DIELECTRIC);
    assert_close(water->index_of_refraction, 1.5, 0);  /* no Ni: 1.5 */
    const scene_material *chrome = &sc.materials[tm[5]];
    assert_string_equal(chrome->name, "chair.obj:chrome");
    assert_int_equal(chrome->type, MATERIAL_METAL);
    assert_close(chrome->albedo[0], 0.9, 1e-6);
    assert_close(chrome->albedo[2], 0.7, 1e-6);
    assert_close(chrome->fuzz, sqrt(2.0 / 1002.0), 1e-6);
    /* the second mesh has its own */
    const int *tm2 = sc.meshes[1].triangle_materials;
    assert_string_equal(sc.materials[tm2[0]].name, "table.obj:clay");
    assert_true(tm2[0] != tm[0]);
    scene_free(&sc);
}

static void test_mtl_non_finite_is_an_error(void **state)
{
    scratch *s = *state;
    write_file(s, "bad.mtl", "newmtl hot\nKe 1e39 0 0\n");
    rt_error error;
    load_fails(s, "hot.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl hot\nf 1 2 3\n", &error);
    assert_contains(error.message, "material 'hot' of '");
    assert_contains(error.message, "bad.mtl' has a value that is not a finite number");
}

/* ---- scene_load_assets: meshes ---------------------------------------------------------- */

static void test_mesh_errors_carry_the_position(void **state)
{
    scratch *s = *state;
    scene sc;
    scene_defaults(&sc);
    add_mesh(&sc, in_scratch(s, "nothere.obj"), -1);
    rt_error error;
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    char expected[1024];
    snprintf(expected, sizeof expected, POSITION ": cannot read mesh '%s': No such file or directory",
             in_scratch(s, "nothere.obj"));
    assert_string_equal(error.message, expected);
    scene_free(&sc);

    scene_defaults(&sc);
    add_mesh(&sc, write_file(s, "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 5\n"), -1);
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    snprintf(expected, sizeof expected,
             POSITION ": cannot read mesh '%s': triangle 1: vertex index 5 is out of range: the file has 3 vertices",
             in_scratch(s, "bad.obj"));
    assert_string_equal(error.message, expected);
    assert_null(sc.meshes[0].positions);
    scene_free(&sc);

    /* a default material that is no material */
    scene_defaults(&sc);
    add_mesh(&sc, write_file(s, "ok.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"), 3);
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    assert_contains(error.message, POSITION ": mesh '");
    assert_contains(error.message, "default material 3");
    scene_free(&sc);
}

static void test_second_call_loads_nothing_twice(void **state)
{
    scratch *s = *state;
    write_file(s, "one.mtl", "newmtl paint\nKd 0.1 0.6 0.1\n");
    const char *path = write_file(s, "one.obj", "mtllib one.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl paint\nf 1 2 3\n");
    scene sc;
    scene_defaults(&sc);
    add_mesh(&sc, path, -1);
    load_scene_ok(&sc);
    assert_int_equal(sc.material_count, 1);
    float *positions = sc.meshes[0].positions;
    load_scene_ok(&sc);
    assert_int_equal(sc.material_count, 1);
    assert_ptr_equal(sc.meshes[0].positions, positions);
    assert_int_equal(sc.meshes[0].triangle_materials[0], 0);
    scene_free(&sc);
}

/* ---- scene_load_assets: images ---------------------------------------------------------- */

static int add_image(scene *s, const char *path)
{
    scene_image image;
    memset(&image, 0, sizeof image);
    snprintf(image.path, sizeof image.path, "%s", path);
    snprintf(image.position, sizeof image.position, "%s", POSITION);
    int index = scene_add_image(s, &image);
    assert_true(index >= 0);
    return index;
}

static void test_png_is_decoded_from_srgb(void **state)
{
    scratch *s = *state;
    /* linear 0.2158605 is stored as 8-bit sRGB 128 */
    const float colour[4] = {0.2158605f, 1.0f, 0.0f, 0.5f};
    write_image(in_scratch(s, "texture.png"), 3, 2, 4, colour);
    rt_image raw;
    rt_error error;
    assert_int_equal(image_read(s->path, &raw, &error), RT_OK);
    assert_close(raw.pixels[0], 128.0 / 255.0, 1e-6);  /* the file holds 128 */
    assert_close(raw.pixels[3], 128.0 / 255.0, 1e-6);  /* alpha 0.5 as 128, linearly */
    image_free(&raw);

    scene sc;
    scene_defaults(&sc);
    int index = add_image(&sc, s->path);
    load_scene_ok(&sc);
    const scene_image *image = &sc.images[index];
    assert_int_equal(image->width, 3);
    assert_int_equal(image->height, 2);
    for (int i = 0; i < 6; i++) {
        assert_close(image->pixels[4 * i + 0], 0.2158605, 2e-4);
        assert_close(image->pixels[4 * i + 1], 1.0, 1e-6);
        assert_close(image->pixels[4 * i + 2], 0.0, 0);
        assert_close(image->pixels[4 * i + 3], 128.0 / 255.0, 1e-6);  /* alpha stays */
    }
    scene_free(&sc);
}

static void test_grey_and_rgb_images_become_rgba(void **state)
{
    scratch *s = *state;
    /* PGM and PPM: OpenImageIO reports them as Rec. 709 encoded */
    char grey_path[512], rgb[512];
    snprintf(grey_path, sizeof grey_path, "%s", write_file(s, "grey.pgm", "P2\n2 1\n255\n128 255\n"));
    snprintf(rgb, sizeof rgb, "%s",
             write_file(s, "rgb.ppm", "P3\n2 2\n255\n255 0 0  0 255 0\n0 0 255  255 255 255\n"));
    const float grey_alpha[2] = {0.2158605f, 0.25f};
    char grey_png[512];
    snprintf(grey_png, sizeof grey_png, "%s", in_scratch(s, "grey-alpha.png"));
    write_image(grey_png, 1, 1, 2, grey_alpha);
    const float one_grey[1] = {1.0f};
    char single[512];
    snprintf(single, sizeof single, "%s", in_scratch(s, "single.png"));
    write_image(single, 1, 1, 1, one_grey);

    scene sc;
    scene_defaults(&sc);
    add_image(&sc, grey_path);
    add_image(&sc, rgb);
    add_image(&sc, grey_png);
    add_image(&sc, single);
    load_scene_ok(&sc);

    const scene_image *g = &sc.images[0];
    assert_int_equal(g->width, 2);
    assert_int_equal(g->height, 1);
    double rec709 = pow((128.0 / 255.0 + 0.099) / 1.099, 1 / 0.45);
    for (int c = 0; c < 3; c++) {
        assert_close(g->pixels[c], rec709, 1e-4);
        assert_close(g->pixels[4 + c], 1.0, 1e-6);
    }
    assert_close(g->pixels[3], 1.0, 0);
    assert_close(g->pixels[7], 1.0, 0);

    const scene_image *c = &sc.images[1];
    const float expected[4][4] = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, 0, 1, 1}, {1, 1, 1, 1}};
    for (int i = 0; i < 4; i++)  /* rows top to bottom as in the file */
        for (int k = 0; k < 4; k++)
            assert_close(c->pixels[4 * i + k], expected[i][k], 1e-6);

    const scene_image *ga = &sc.images[2];
    for (int k = 0; k < 3; k++)
        assert_close(ga->pixels[k], 0.2158605, 2e-4);
    assert_close(ga->pixels[3], 64.0 / 255.0, 1e-6);  /* alpha 0.25 -> 64, kept linear */

    const scene_image *one = &sc.images[3];
    for (int k = 0; k < 4; k++)
        assert_close(one->pixels[k], 1.0, 1e-6);
    scene_free(&sc);
}

static void test_image_errors_carry_the_position(void **state)
{
    scratch *s = *state;
    scene sc;
    scene_defaults(&sc);
    add_image(&sc, in_scratch(s, "nothere.png"));
    rt_error error;
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    char expected[1024];
    snprintf(expected, sizeof expected, POSITION ": cannot read image '%s': No such file or directory",
             in_scratch(s, "nothere.png"));
    assert_string_equal(error.message, expected);
    assert_null(sc.images[0].pixels);
    scene_free(&sc);

    /* larger than the GPU holds: refused */
    const float black[3] = {0, 0, 0};
    char wide[512];
    snprintf(wide, sizeof wide, "%s", in_scratch(s, "wide.png"));
    write_image(wide, SCENE_IMAGE_MAX_SIDE + 1, 1, 3, black);
    scene_defaults(&sc);
    add_image(&sc, wide);
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    snprintf(expected, sizeof expected, POSITION ": cannot read image '%s': it is 16385x1 pixels, more than 16384 on a side",
             wide);
    assert_string_equal(error.message, expected);
    scene_free(&sc);

    /* a NaN pixel in an EXR */
    const float bad[3] = {0.5f, NAN, 0.5f};
    char nan_path[512];
    snprintf(nan_path, sizeof nan_path, "%s", in_scratch(s, "nan.exr"));
    write_image(nan_path, 2, 2, 3, bad);
    scene_defaults(&sc);
    add_image(&sc, nan_path);
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    assert_contains(error.message, POSITION ": image '");
    assert_contains(error.message, "not a finite number");
    scene_free(&sc);
}

static void test_exr_stays_linear(void **state)
{
    scratch *s = *state;
    const float value[3] = {0.2f, 3.5f, 0.0f};
    char path[512];
    snprintf(path, sizeof path, "%s", in_scratch(s, "sky.exr"));
    write_image(path, 2, 1, 3, value);
    scene sc;
    scene_defaults(&sc);
    add_image(&sc, path);
    load_scene_ok(&sc);
    assert_close(sc.images[0].pixels[0], 0.2, 1e-6);
    assert_close(sc.images[0].pixels[1], 3.5, 0);
    assert_close(sc.images[0].pixels[3], 1.0, 0);
    scene_free(&sc);
}

/* ---- sky box ---------------------------------------------------------------------------- */

static const char *const face_files[SKY_FACE_COUNT] = {"px.png", "nx.png", "py.png", "ny.png", "pz.png", "nz.png"};

/* A scene whose sky box faces are 4x4 except face odd (odd_width x odd_height). */
static void make_sky_box(scratch *s, scene *sc, int odd, int odd_width, int odd_height)
{
    const float blue[3] = {0.1f, 0.2f, 0.9f};
    scene_defaults(sc);
    sc->sky.type = SKY_BOX;
    for (int f = 0; f < SKY_FACE_COUNT; f++) {
        char path[512];
        snprintf(path, sizeof path, "%s", in_scratch(s, face_files[f]));
        write_image(path, f == odd ? odd_width : 4, f == odd ? odd_height : 4, 3, blue);
        sc->sky.faces[f] = add_image(sc, path);
    }
}

static void test_sky_box_faces_must_match(void **state)
{
    scratch *s = *state;
    scene sc;
    make_sky_box(s, &sc, -1, 0, 0);
    load_scene_ok(&sc);
    scene_free(&sc);

    make_sky_box(s, &sc, SKY_FACE_POSITIVE_Y, 2, 2);
    rt_error error;
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    char expected[1024];
    snprintf(expected, sizeof expected, POSITION ": sky box: the +Y face '%s' is 2x2, the +X face is 4x4",
             in_scratch(s, "py.png"));
    assert_string_equal(error.message, expected);
    scene_free(&sc);

    make_sky_box(s, &sc, SKY_FACE_NEGATIVE_Z, 4, 3);
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    snprintf(expected, sizeof expected, POSITION ": sky box: the -Z face '%s' is 4x3; the faces must be square",
             in_scratch(s, "nz.png"));
    assert_string_equal(error.message, expected);
    scene_free(&sc);

    make_sky_box(s, &sc, -1, 0, 0);
    sc.sky.faces[SKY_FACE_NEGATIVE_X] = -1;
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "sky box: the -X face has no image");
    scene_free(&sc);
}

/* An unreadable face is named as a face too, not only by its file and position. */
static void test_sky_box_unreadable_face_is_named(void **state)
{
    scratch *s = *state;
    scene sc;
    make_sky_box(s, &sc, -1, 0, 0);
    assert_int_equal(remove(in_scratch(s, "ny.png")), 0);
    rt_error error;
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    char expected[1024];
    snprintf(expected, sizeof expected, POSITION ": sky box: cannot read the -Y face image '%s': No such file or "
             "directory", in_scratch(s, "ny.png"));
    assert_string_equal(error.message, expected);
    scene_free(&sc);

    /* One file for two faces: both are named. */
    make_sky_box(s, &sc, -1, 0, 0);
    assert_int_equal(remove(in_scratch(s, "pz.png")), 0);
    sc.sky.faces[SKY_FACE_NEGATIVE_Z] = sc.sky.faces[SKY_FACE_POSITIVE_Z];
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    snprintf(expected, sizeof expected, POSITION ": sky box: cannot read the +Z/-Z face image '%s': No such file or "
             "directory", in_scratch(s, "pz.png"));
    assert_string_equal(error.message, expected);
    scene_free(&sc);

    /* A face that is not an image at all. */
    make_sky_box(s, &sc, -1, 0, 0);
    write_file(s, "px.png", "not a png");
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    snprintf(expected, sizeof expected, POSITION ": sky box: cannot read the +X face image '%s': ",
             in_scratch(s, "px.png"));
    assert_contains(error.message, expected);
    scene_free(&sc);

    /* The same file as a texture's image, with no sky box: an image, as before. */
    assert_int_equal(remove(in_scratch(s, "ny.png")), 0);
    scene_defaults(&sc);
    add_image(&sc, in_scratch(s, "ny.png"));
    assert_int_equal(scene_load_assets(&sc, &error), RT_ERROR_INPUT);
    snprintf(expected, sizeof expected, POSITION ": cannot read image '%s': No such file or directory",
             in_scratch(s, "ny.png"));
    assert_string_equal(error.message, expected);
    scene_free(&sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
#define T(name) scratch_test(name)
        T(test_quad_becomes_two_triangles),
        T(test_ngons_are_triangulated),
        T(test_negative_indices),
        T(test_missing_normals_and_uvs),
        T(test_vertices_unify_position_normal_uv),
        T(test_partly_missing_normals_get_the_face_normal),
    T(test_normals_stay_unit_near_the_float_range),
        T(test_crlf_bom_comments_and_groups),
        T(test_malformed_lines),
        T(test_tinyobjloader_reads_leniently),
        T(test_out_of_range_indices),
        T(test_empty_files_have_no_faces),
        T(test_non_finite_numbers),
        T(test_missing_and_directory_files),
        T(test_missing_mtl_still_loads),
        T(test_missing_mtl_in_a_scene),
        T(test_tinyobjloader_warnings_are_kept),
        T(test_usemtl_names_without_a_definition_are_kept),
        T(test_volume_mesh_too_small_to_close),
        T(test_usemtl_names_scene_materials),
        T(test_mtl_materials_become_scene_materials),
        T(test_mtl_non_finite_is_an_error),
        T(test_mesh_errors_carry_the_position),
        T(test_second_call_loads_nothing_twice),
        T(test_png_is_decoded_from_srgb),
        T(test_grey_and_rgb_images_become_rgba),
        T(test_image_errors_carry_the_position),
        T(test_exr_stays_linear),
        T(test_sky_box_faces_must_match),
        T(test_sky_box_unreadable_face_is_named),
#undef T
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
