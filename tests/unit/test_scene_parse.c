/* test_scene_parse.c: unit tests of the scene text parser (core/scene_parse.c). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "scene_parse.h"
#include "support.h"

/* ------------------------------------------------------------------ helpers */

#define assert_vector_equal(vector, x, y, z)            \
    do {                                                \
        assert_double_equal((vector)[0], (x), 1e-6);    \
        assert_double_equal((vector)[1], (y), 1e-6);    \
        assert_double_equal((vector)[2], (z), 1e-6);    \
    } while (0)

/* True when *s is byte for byte what scene_defaults() makes (scene_free leaves that too). */
static bool scene_is_default(const scene *s)
{
    scene defaults;
    scene_defaults(&defaults);
    return memcmp(s, &defaults, sizeof defaults) == 0;
}

/* Parses text (named "s.txt") and fails the test unless it succeeds. The caller frees *out. */
#define parse_ok(text, options, out) check_parse_ok((text), "s.txt", (options), (out), __FILE__, __LINE__)

static void check_parse_ok(const char *text, const char *name, const scene_parse_options *options, scene *out,
                           const char *file, int line)
{
    rt_error error = {{0}};
    rt_status status = scene_load_string(text, name, options, out, &error);
    if (status != RT_OK) {
        print_error("parsing failed with status %d: %s\n", status, error.message);
        _fail(file, line);
    }
}

/* Parses text (named "s.txt") and checks that it fails with RT_ERROR_INPUT, that the
 * message starts with prefix (usually "FILE:LINE:COLUMN: ") and contains phrase (ends
 * with it, when phrase ends in '$'), and that the output scene is left as
 * scene_defaults(). */
#define assert_parse_error(text, prefix, phrase) \
    check_parse_error((text), NULL, (prefix), (phrase), __FILE__, __LINE__)
#define assert_parse_error_with(text, options, prefix, phrase) \
    check_parse_error((text), (options), (prefix), (phrase), __FILE__, __LINE__)

/* The checks shared by string and file errors; see assert_parse_error. */
static void check_message(rt_status status, const char *message, const scene *s, const char *prefix,
                          const char *phrase, const char *file, int line)
{
    if (status != RT_ERROR_INPUT) {
        print_error("expected RT_ERROR_INPUT with '%s%s', got status %d (%s)\n", prefix, phrase, status, message);
        _fail(file, line);
    }
    /* A phrase ending in '$' must end the message (so "found -0.1$" rejects -0.1000001). */
    size_t phrase_length = strlen(phrase), message_length = strlen(message);
    bool at_end = phrase_length > 0 && phrase[phrase_length - 1] == '$';
    bool phrase_found = at_end ? message_length >= phrase_length - 1 &&
                                     strncmp(message + message_length - (phrase_length - 1), phrase,
                                             phrase_length - 1) == 0
                               : strstr(message, phrase) != NULL;
    if (strncmp(message, prefix, strlen(prefix)) != 0 || !phrase_found) {
        print_error("expected a message starting with '%s' and containing '%s', got:\n  %s\n", prefix, phrase,
                    message);
        _fail(file, line);
    }
    if (!scene_is_default(s)) {
        print_error("the scene was not left as scene_defaults() after: %s\n", message);
        _fail(file, line);
    }
}

/* See assert_parse_error. */
static void check_parse_error(const char *text, const scene_parse_options *options, const char *prefix,
                              const char *phrase, const char *file, int line)
{
    scene s;
    rt_error error = {{0}};
    rt_status status = scene_load_string(text, "s.txt", options, &s, &error);
    check_message(status, error.message, &s, prefix, phrase, file, line);
}

/* Returns default options with the given -D defines. */
static scene_parse_options options_with_defines(const scene_define *defines, int count)
{
    scene_parse_options options = scene_parse_options_defaults();
    options.defines = defines;
    options.define_count = count;
    return options;
}

/* ---- file tests: each gets a scratch directory (support.h) as its state */

/* Returns "DIRECTORY/name" in buffer. */
static const char *path_in(void **state, const char *name, char *buffer, size_t size)
{
    if (snprintf(buffer, size, "%s", in_scratch(*state, name)) >= (int)size)
        fail_msg("the path of %s is too long", name);
    return buffer;
}

/* Writes length bytes of content to DIRECTORY/name, making its subdirectories. */
static void write_bytes(void **state, const char *name, const char *content, size_t length)
{
    scratch_write(*state, name, content, length);
}

/* Writes the string content to DIRECTORY/name. */
static void write_text(void **state, const char *name, const char *content)
{
    write_file(*state, name, content);
}

/* Loads DIRECTORY/name and checks the error as check_parse_error does; prefix and
 * phrase may contain one "%s" each, replaced by the directory. */
#define assert_file_error(state, name, options, prefix, phrase) \
    check_file_error((state), (name), (options), (prefix), (phrase), __FILE__, __LINE__)

/* See assert_file_error. */
static void check_file_error(void **state, const char *name, const scene_parse_options *options,
                             const char *prefix_format, const char *phrase_format, const char *file, int line)
{
    const char *directory = ((scratch *)*state)->directory;
    char path[256], prefix[512], phrase[1024];
    path_in(state, name, path, sizeof path);
    snprintf(prefix, sizeof prefix, prefix_format, directory);
    snprintf(phrase, sizeof phrase, phrase_format, directory, directory, directory, directory);
    scene s;
    rt_error error = {{0}};
    rt_status status = scene_load_file(path, options, &s, &error);
    check_message(status, error.message, &s, prefix, phrase, file, line);
}

/* Loads DIRECTORY/name into *out, failing the test unless it succeeds; the caller frees *out. */
static void load_file_ok(void **state, const char *name, const scene_parse_options *options, scene *out)
{
    char path[256];
    rt_error error = {{0}};
    rt_status status = scene_load_file(path_in(state, name, path, sizeof path), options, out, &error);
    if (status != RT_OK)
        fail_msg("loading %s failed: %s", name, error.message);
}

/* ------------------------------------------------------------------ defaults and statements */

static void test_empty_text_gives_defaults(void **state)
{
    (void)state;
    scene s;
    parse_ok("", NULL, &s);
    assert_true(scene_is_default(&s));
    assert_int_equal(s.render.width, 640);
    assert_int_equal(s.render.height, 360);
    assert_int_equal(s.render.samples_per_pixel, 64);
    assert_int_equal(s.render.max_depth, 16);
    assert_int_equal(s.render.seed, 1);
    assert_vector_equal(s.camera.look_from, 0, 0, 1);
    assert_double_equal(s.camera.vertical_fov_degrees, 40, 0);
    assert_int_equal(s.sky.type, SKY_GRADIENT);
    scene_free(&s);

    parse_ok("# only a comment\n\n   \t\n# another\n", NULL, &s);
    assert_true(scene_is_default(&s));
    scene_free(&s);

    scene_parse_options options = scene_parse_options_defaults();
    assert_null(options.defines);
    assert_int_equal(options.define_count, 0);
    assert_int_equal(options.max_include_depth, 0);
    parse_ok("\n", &options, &s);
    assert_true(scene_is_default(&s));
    scene_free(&s);
}

static void test_camera_clauses(void **state)
{
    (void)state;
    scene s;
    parse_ok("camera from 1 2 3 at 4 5 6 up 0 0 1 fov 50 aperture 0.1 focus 7.5\n", NULL, &s);
    assert_vector_equal(s.camera.look_from, 1, 2, 3);
    assert_vector_equal(s.camera.look_at, 4, 5, 6);
    assert_vector_equal(s.camera.up, 0, 0, 1);
    assert_double_equal(s.camera.vertical_fov_degrees, 50, 1e-6);
    assert_double_equal(s.camera.aperture, 0.1, 1e-7);
    assert_double_equal(s.camera.focus_distance, 7.5, 0);
    scene_free(&s);

    /* Any order, and a clause left out keeps its default. */
    parse_ok("camera focus 2 fov 179.5 at 0 1 0 from 0 1 5", NULL, &s);
    assert_vector_equal(s.camera.look_from, 0, 1, 5);
    assert_vector_equal(s.camera.look_at, 0, 1, 0);
    assert_vector_equal(s.camera.up, 0, 1, 0);
    assert_double_equal(s.camera.vertical_fov_degrees, 179.5, 1e-5);
    assert_double_equal(s.camera.aperture, 0, 0);
    assert_double_equal(s.camera.focus_distance, 2, 0);
    scene_free(&s);

    /* Several statements: later clauses override earlier ones. A bare camera is fine. */
    parse_ok("camera fov 30 from 0 0 9\ncamera\ncamera fov 60\n", NULL, &s);
    assert_double_equal(s.camera.vertical_fov_degrees, 60, 0);
    assert_vector_equal(s.camera.look_from, 0, 0, 9);
    scene_free(&s);
}

static void test_render_clauses(void **state)
{
    (void)state;
    scene s;
    parse_ok("render size 320 200 spp 16 depth 8 seed 42", NULL, &s);
    assert_int_equal(s.render.width, 320);
    assert_int_equal(s.render.height, 200);
    assert_int_equal(s.render.samples_per_pixel, 16);
    assert_int_equal(s.render.max_depth, 8);
    assert_int_equal(s.render.seed, 42);
    scene_free(&s);

    parse_ok("render seed 4294967295 depth 100000\nrender spp (2^30) size 65536 1\nrender seed 0", NULL, &s);
    assert_int_equal(s.render.seed, 0);
    assert_int_equal(s.render.max_depth, 100000);
    assert_int_equal(s.render.samples_per_pixel, 1073741824);
    assert_int_equal(s.render.width, 65536);
    assert_int_equal(s.render.height, 1);
    scene_free(&s);

    parse_ok("render seed 4294967295", NULL, &s);
    assert_int_equal(s.render.seed, 4294967295u);
    scene_free(&s);
}

static void test_sky(void **state)
{
    (void)state;
    scene s;
    parse_ok("sky gradient 0.1 0.2 0.3  0.4 0.5 0.6", NULL, &s);
    assert_int_equal(s.sky.type, SKY_GRADIENT);
    assert_vector_equal(s.sky.bottom, 0.1, 0.2, 0.3);
    assert_vector_equal(s.sky.top, 0.4, 0.5, 0.6);
    scene_free(&s);

    parse_ok("sky gradient 0 0 0 1 1 1\nsky constant 2 3 4", NULL, &s);
    assert_int_equal(s.sky.type, SKY_CONSTANT);
    assert_vector_equal(s.sky.bottom, 2, 3, 4);
    assert_vector_equal(s.sky.top, 2, 3, 4);
    scene_free(&s);

    parse_ok("sky constant 1 1 1\nsky gradient 0 0 0 1 1 1", NULL, &s);   /* the last sky wins */
    assert_int_equal(s.sky.type, SKY_GRADIENT);
    assert_vector_equal(s.sky.bottom, 0, 0, 0);
    scene_free(&s);
}

static void test_materials(void **state)
{
    (void)state;
    scene s;
    parse_ok("material matte lambertian 0.5 0.25 0.125\n"
             "material shiny metal 0.9 0.8 0.7\n"
             "material brushed metal 0.9 0.8 0.7 fuzz 0.3\n"
             "material glass dielectric 1.5\n"
             "material lamp emissive 1 0.5 0.25\n"
             "material bright emissive 1 0.5 0.25 strength 4\n"
             "material dark-lamp.2 emissive 1 1 1 strength 0\n", NULL, &s);
    assert_int_equal(s.material_count, 7);

    assert_string_equal(s.materials[0].name, "matte");
    assert_int_equal(s.materials[0].type, MATERIAL_LAMBERTIAN);
    assert_vector_equal(s.materials[0].albedo, 0.5, 0.25, 0.125);
    assert_vector_equal(s.materials[0].emission, 0, 0, 0);
    assert_double_equal(s.materials[0].fuzz, 0, 0);
    assert_double_equal(s.materials[0].index_of_refraction, 0, 0);

    assert_int_equal(s.materials[1].type, MATERIAL_METAL);
    assert_vector_equal(s.materials[1].albedo, 0.9, 0.8, 0.7);
    assert_double_equal(s.materials[1].fuzz, 0, 0);              /* default fuzz */
    assert_int_equal(s.materials[2].type, MATERIAL_METAL);
    assert_double_equal(s.materials[2].fuzz, 0.3, 1e-7);

    assert_int_equal(s.materials[3].type, MATERIAL_DIELECTRIC);
    assert_double_equal(s.materials[3].index_of_refraction, 1.5, 0);
    assert_vector_equal(s.materials[3].albedo, 0, 0, 0);

    assert_int_equal(s.materials[4].type, MATERIAL_EMISSIVE);
    assert_vector_equal(s.materials[4].emission, 1, 0.5, 0.25);  /* default strength 1 */
    assert_vector_equal(s.materials[4].albedo, 0, 0, 0);
    assert_vector_equal(s.materials[5].emission, 4, 2, 1);       /* colour x strength */
    assert_string_equal(s.materials[6].name, "dark-lamp.2");
    assert_vector_equal(s.materials[6].emission, 0, 0, 0);
    scene_free(&s);

    /* The fuzz and strength of the boundaries are valid. */
    parse_ok("material a metal 1 1 1 fuzz 1\nmaterial b metal 0 0 0 fuzz 0\nmaterial c lambertian 0 0 0", NULL, &s);
    assert_double_equal(s.materials[0].fuzz, 1, 0);
    scene_free(&s);
}

static void test_spheres(void **state)
{
    (void)state;
    scene s;
    parse_ok("material red lambertian 1 0 0\nmaterial blue lambertian 0 0 1\n"
             "sphere 1 2 3 0.5 blue\nsphere -1 -2.5 .5 1e-3 red\nsphere +3 0 0 100 blue\n", NULL, &s);
    assert_int_equal(s.sphere_count, 3);
    assert_vector_equal(s.spheres[0].center, 1, 2, 3);
    assert_double_equal(s.spheres[0].radius, 0.5, 0);
    assert_int_equal(s.spheres[0].material, 1);
    assert_vector_equal(s.spheres[1].center, -1, -2.5, 0.5);
    assert_double_equal(s.spheres[1].radius, 1e-3, 1e-10);
    assert_int_equal(s.spheres[1].material, 0);
    assert_vector_equal(s.spheres[2].center, 3, 0, 0);
    scene_free(&s);
}

static void test_comments_spacing_and_line_endings(void **state)
{
    (void)state;
    scene s;
    parse_ok("material m lambertian 1 1 1 # a comment\n"
             "\t sphere\t0 0 0   1 m#comment right after a token\n"
             "render spp 2\r\n"
             "camera fov 30\r\n"
             "   # indented comment\n"
             "render depth 3", NULL, &s);
    assert_int_equal(s.sphere_count, 1);
    assert_int_equal(s.render.samples_per_pixel, 2);
    assert_double_equal(s.camera.vertical_fov_degrees, 30, 0);
    assert_int_equal(s.render.max_depth, 3);
    scene_free(&s);

    /* A UTF-8 byte order mark is skipped; UTF-8 text in comments is fine. */
    parse_ok("\xEF\xBB\xBF" "camera fov 20 # café ✓ 日本\n", NULL, &s);
    assert_double_equal(s.camera.vertical_fov_degrees, 20, 0);
    scene_free(&s);
}

/* ------------------------------------------------------------------ numbers and variables */

static void test_number_forms(void **state)
{
    (void)state;
    scene s;
    parse_ok("set y 2\n"
             "set t 0\n"
             "material m lambertian 1 1 1\n"
             "sphere (1 + 2) (-$y) ( 4*cos($t) ) $y m\n"
             "sphere -2.5 .5 1e-3 +3 m\n"
             "sphere (2*pi) (sqrt(16) - max(1, 2)) (-2^2) (1/4) m\n", NULL, &s);
    assert_vector_equal(s.spheres[0].center, 3, -2, 4);
    assert_double_equal(s.spheres[0].radius, 2, 0);
    assert_vector_equal(s.spheres[1].center, -2.5, 0.5, 1e-3);
    assert_double_equal(s.spheres[1].radius, 3, 0);
    assert_vector_equal(s.spheres[2].center, 2 * 3.14159265358979, 2, -4);
    assert_double_equal(s.spheres[2].radius, 0.25, 0);
    scene_free(&s);
}

static void test_set_and_variables(void **state)
{
    (void)state;
    scene s;
    parse_ok("set a 2\n"
             "set b $a * 3        # the rest of the line is one expression\n"
             "set angle 2*pi*0.25\n"
             "set a 5             # setting again is allowed: later wins\n"
             "set a $a + 1\n"
             "set _Long_name9 (1)\n"
             "camera fov ($b * 10) aperture $_Long_name9\n"
             "render spp $a\n"
             "camera focus (sin($angle))\n", NULL, &s);
    assert_double_equal(s.camera.vertical_fov_degrees, 60, 0);
    assert_double_equal(s.camera.aperture, 1, 0);
    assert_int_equal(s.render.samples_per_pixel, 6);
    assert_double_equal(s.camera.focus_distance, 1, 1e-7);
    scene_free(&s);
}

static void test_variable_must_be_set_before_use(void **state)
{
    (void)state;
    assert_parse_error("material m lambertian 1 1 1\nsphere 0 0 0 $r m\nset r 1\n", "s.txt:2:14: ",
                       "undefined variable $r");
    assert_parse_error("set angle 2*pi*$t", "s.txt:1:16: ", "undefined variable $t");
    assert_parse_error("set x $x + 1", "s.txt:1:7: ", "undefined variable $x");
}

static void test_set_errors(void **state)
{
    (void)state;
    assert_parse_error("set", "s.txt:1:4: ", "expected a variable name after set, found end of line");
    assert_parse_error("set x", "s.txt:1:6: ", "expected an expression for $x, found end of line");
    assert_parse_error("set x   # nothing", "s.txt:1:6: ", "expected an expression for $x");
    assert_parse_error("set 1x 2", "s.txt:1:5: ", "expected a variable name after set");
    assert_parse_error("set $x 2", "s.txt:1:5: ", "write it without '$'");
    assert_parse_error("set a-b 2", "s.txt:1:5: ", "found 'a-b'");
    assert_parse_error("set x 1 +", "s.txt:1:10: ", "expected a number, $variable, function or '('");
    assert_parse_error("set x (1 + 2", "s.txt:1:7: ", "unbalanced parentheses");
    assert_parse_error("set x 2 3", "s.txt:1:9: ", "unexpected character '3'");
}

/* ------------------------------------------------------------------ expression errors in scenes */

static void test_expression_errors_have_scene_positions(void **state)
{
    (void)state;
    assert_parse_error("camera fov (1/0)", "s.txt:1:14: ", "division by zero");
    assert_parse_error("camera fov (foo(1))", "s.txt:1:13: ", "unknown function 'foo'");
    assert_parse_error("camera fov (min(1))", "s.txt:1:13: ", "min takes 2 arguments, found 1");
    assert_parse_error("camera fov (1 + 2", "s.txt:1:12: ", "unbalanced parentheses: this '(' is never closed");
    assert_parse_error("camera fov (1 + 2  # comment", "s.txt:1:12: ", "never closed");
    assert_parse_error("camera fov (10))", "s.txt:1:16: ", "unbalanced parentheses: ')' has no matching '('");
    assert_parse_error("camera fov (1 @ 2)", "s.txt:1:15: ", "unexpected character '@'");
    assert_parse_error("camera fov ()", "s.txt:1:12: ", "empty expression");
    assert_parse_error("camera fov ($nope)", "s.txt:1:13: ", "undefined variable $nope");
    assert_parse_error("camera fov $nope", "s.txt:1:12: ", "undefined variable $nope");
    assert_parse_error("camera fov (sqrt(-4))", "s.txt:1:13: ", "sqrt of a negative number (-4)");
    assert_parse_error("camera aperture (1e308*10)", "s.txt:1:23: ", "the result of '*' is infinite");
    assert_parse_error("camera fov (0^-1)", "s.txt:1:14: ", "the result of '^' is infinite");
    assert_parse_error("camera fov (1e999)", "s.txt:1:13: ", "out of range");
    assert_parse_error("camera fov (nan)", "s.txt:1:13: ", "unknown name 'nan'");
    assert_parse_error("camera fov (1 { 2)", "s.txt:1:15: ", "unexpected character '{'");
}

static void test_bad_number_tokens(void **state)
{
    (void)state;
    assert_parse_error("material m lambertian 1 1 1\nsphere 0 0 0 abc m", "s.txt:2:14: ",
                       "expected a number for the sphere's radius, found 'abc'");
    assert_parse_error("sphere 1.2.3 0 0 1 m", "s.txt:1:8: ", "expected a number for the sphere's center x, found '1.2.3'");
    assert_parse_error("camera fov 2*3", "s.txt:1:12: ", "write an expression in parentheses");
    assert_parse_error("camera fov 2+", "s.txt:1:12: ", "found '2+'");
    assert_parse_error("camera fov \"30\"", "s.txt:1:12: ", "expected a number for the camera's fov, found the string \"30\"");
    assert_parse_error("camera fov $1x", "s.txt:1:12: ", "found '$1x'");
    assert_parse_error("camera fov $a+1", "s.txt:1:12: ", "found '$a+1'");
    assert_parse_error("camera fov (1+2)*3", "s.txt:1:12: ", "entirely inside one pair of parentheses");
    assert_parse_error("camera fov 1e", "s.txt:1:12: ", "found '1e'");
    assert_parse_error("camera fov 0x10", "s.txt:1:12: ", "found '0x10'");
    assert_parse_error("camera fov sin(1)", "s.txt:1:12: ", "found 'sin(1)'");
    assert_parse_error("camera fov -", "s.txt:1:12: ", "found '-'");
}

static void test_non_finite_numbers(void **state)
{
    (void)state;
    assert_parse_error("camera fov nan", "s.txt:1:12: ", "found 'nan' (NaN and infinity are not allowed)");
    assert_parse_error("camera fov -inf", "s.txt:1:12: ", "NaN and infinity are not allowed");
    assert_parse_error("camera fov Infinity", "s.txt:1:12: ", "NaN and infinity are not allowed");
    assert_parse_error("camera fov NAN", "s.txt:1:12: ", "NaN and infinity are not allowed");
    assert_parse_error("camera fov 1e999", "s.txt:1:12: ",
                       "expected a finite number for the camera's fov, found '1e999' (out of range)");
    assert_parse_error("camera fov -1e999", "s.txt:1:12: ", "out of range");
    /* Finite as a double but not as the renderer's float. */
    assert_parse_error("material m lambertian 1 1 1\nsphere 0 0 0 1e300 m", "s.txt:2:14: ",
                       "too large for the renderer's 32-bit floats");
    assert_parse_error("material m emissive 1 1 1 strength 1e38\nmaterial n emissive 10 1 1 strength 1e38",
                       "s.txt:2:37: ", "too large");
}

static void test_value_ranges(void **state)
{
    (void)state;
    const char *m = "material m lambertian 1 1 1\n";
    char text[256];
    snprintf(text, sizeof text, "%ssphere 0 0 0 0 m", m);
    assert_parse_error(text, "s.txt:2:14: ", "the sphere's radius must be > 0, found 0");
    snprintf(text, sizeof text, "%ssphere 0 0 0 -1 m", m);
    assert_parse_error(text, "s.txt:2:14: ", "the sphere's radius must be > 0, found -1");

    assert_parse_error("camera fov 0", "s.txt:1:12: ", "the camera's fov must be between 0 and 180");
    assert_parse_error("camera fov 180", "s.txt:1:12: ", "found 180");
    assert_parse_error("camera fov -5", "s.txt:1:12: ", "between 0 and 180");
    assert_parse_error("camera aperture -0.1", "s.txt:1:17: ", "the camera's aperture must be >= 0, found -0.1$");
    assert_parse_error("camera focus -1", "s.txt:1:14: ", "the camera's focus distance must be >= 0");

    assert_parse_error("material m lambertian 0.5 -0.1 0.5", "s.txt:1:27: ",
                       "the green component of material 'm' must be >= 0, found -0.1$");
    assert_parse_error("sky constant 1 1 -1", "s.txt:1:18: ", "the blue component of the sky colour must be >= 0");
    assert_parse_error("sky gradient 1 1 1 -2 1 1", "s.txt:1:20: ", "the red component of the sky's top colour");
    assert_parse_error("material m metal 1 1 1 fuzz 1.5", "s.txt:1:29: ",
                       "the fuzz of material 'm' must be between 0 and 1, found 1.5$");
    assert_parse_error("material m metal 1 1 1 fuzz -0.1", "s.txt:1:29: ", "between 0 and 1");
    assert_parse_error("material g dielectric 0", "s.txt:1:23: ",
                       "the index of refraction of material 'g' must be > 0, found 0");
    assert_parse_error("material g dielectric -1.5", "s.txt:1:23: ", "must be > 0");
    assert_parse_error("material l emissive 1 1 1 strength -1", "s.txt:1:36: ",
                       "the strength of material 'l' must be >= 0, found -1");
    assert_parse_error("material l emissive 1 -1 1", "s.txt:1:23: ", "the green component of material 'l'");
    /* Positive in double but zero as a float is no better than zero. */
    snprintf(text, sizeof text, "%ssphere 0 0 0 1e-50 m", m);
    assert_parse_error(text, "s.txt:2:14: ", "the sphere's radius 1e-50 is too small");
    assert_parse_error("material g dielectric 1e-60", "s.txt:1:23: ", "too small");
}

static void test_integer_ranges(void **state)
{
    (void)state;
    assert_parse_error("render size 0 10", "s.txt:1:13: ",
                       "the render width must be a whole number from 1 to 65536, found 0");
    assert_parse_error("render size 10 65537", "s.txt:1:16: ", "the render height must be a whole number from 1 to 65536");
    assert_parse_error("render size 10.5 10", "s.txt:1:13: ", "found 10.5");
    assert_parse_error("render spp 0", "s.txt:1:12: ", "from 1 to 1073741824, found 0");
    assert_parse_error("render spp 1073741825", "s.txt:1:12: ", "from 1 to 1073741824");
    assert_parse_error("render depth 100001", "s.txt:1:14: ", "the render depth must be a whole number from 1 to 100000");
    assert_parse_error("render seed -1", "s.txt:1:13: ", "the render seed must be a whole number from 0 to 4294967295");
    assert_parse_error("render seed 4294967296", "s.txt:1:13: ", "found 4294967296");
    assert_parse_error("render depth (1/3)", "s.txt:1:14: ", "found 0.333333333333333$");
}

/* ------------------------------------------------------------------ statement errors */

static void test_unknown_statement(void **state)
{
    (void)state;
    assert_parse_error("spere 0 0 0 1 m", "s.txt:1:1: ",
                       "unknown statement 'spere' (expected include, set, camera, render, sky, ambient, light, "
                       "texture, material, sphere, moving_sphere, triangle, quad, box, mesh, gltf, group, instance, "
                       "volume, translate, rotate, scale or matrix)");
    assert_parse_error("\n\n   Camera fov 30", "s.txt:3:4: ", "unknown statement 'Camera'");
    assert_parse_error("\"camera\"", "s.txt:1:1: ", "unknown statement the string \"camera\"");
    assert_parse_error("42", "s.txt:1:1: ", "unknown statement '42'");
}

static void test_unknown_clause(void **state)
{
    (void)state;
    assert_parse_error("camera from 0 0 1 zoom 2", "s.txt:1:19: ",
                       "unknown camera clause 'zoom' (expected from, at, up, fov, aperture, focus or shutter)");
    assert_parse_error("render size 10 10 quality 3", "s.txt:1:19: ",
                       "unknown render clause 'quality' (expected size, spp, depth or seed)");
    assert_parse_error("camera from 0 0 1 2", "s.txt:1:19: ", "unknown camera clause '2'");
    assert_parse_error("material m metal 1 1 1 shine 2", "s.txt:1:24: ",
                       "unknown metal material clause 'shine' (expected fuzz, normal_map, phong or specular)");
    assert_parse_error("material m emissive 1 1 1 fuzz 2", "s.txt:1:27: ",
                       "unknown emissive material clause 'fuzz' (expected strength, one_sided or group)");
    assert_parse_error("sky rainbow 1 1 1", "s.txt:1:5: ",
                       "expected a sky type (gradient, constant, box or environment), found 'rainbow'");
    assert_parse_error("sky constant 1 1 1 rotate 3", "s.txt:1:20: ", "unknown sky clause 'rotate' (expected intensity or group)");
    assert_parse_error("material m plastic 1 1 1", "s.txt:1:12: ",
                       "expected a material type (lambertian, metal, dielectric, emissive or pbr), found 'plastic'");
}

static void test_repeated_clause(void **state)
{
    (void)state;
    assert_parse_error("camera fov 30 fov 40", "s.txt:1:15: ", "camera clause 'fov' given twice in one statement (first at column 8)");
    assert_parse_error("render seed 1 size 2 2 seed 3", "s.txt:1:24: ", "render clause 'seed' given twice");
    assert_parse_error("material m metal 1 1 1 fuzz 0.1 fuzz 0.2", "s.txt:1:33: ", "clause 'fuzz' given twice");
    assert_parse_error("material m emissive 1 1 1 strength 1 strength 2", "s.txt:1:38: ", "clause 'strength' given twice");
}

static void test_missing_arguments(void **state)
{
    (void)state;
    assert_parse_error("material m lambertian 1 1 1\nsphere 0 0 0", "s.txt:2:13: ",
                       "expected a number for the sphere's radius, found end of line");
    assert_parse_error("sphere 0 0 0   # radius forgotten", "s.txt:1:13: ", "the sphere's radius, found end of line");
    assert_parse_error("sphere 1 2 3 1", "s.txt:1:15: ", "expected a material name for the sphere, found end of line");
    assert_parse_error("sphere", "s.txt:1:7: ", "expected a number for the sphere's center x, found end of line");
    assert_parse_error("camera from 1 2", "s.txt:1:16: ", "expected a number for the camera's from z, found end of line");
    assert_parse_error("camera up 1 0", "s.txt:1:14: ", "the camera's up z");
    assert_parse_error("camera at", "s.txt:1:10: ", "the camera's at x");
    assert_parse_error("camera fov", "s.txt:1:11: ", "expected a number for the camera's fov, found end of line");
    assert_parse_error("camera aperture", "s.txt:1:16: ", "the camera's aperture, found end of line");
    assert_parse_error("camera focus", "s.txt:1:13: ", "the camera's focus distance, found end of line");
    assert_parse_error("render size 10", "s.txt:1:15: ", "expected a number for the render height, found end of line");
    assert_parse_error("render spp", "s.txt:1:11: ", "the samples per pixel (spp), found end of line");
    assert_parse_error("render depth", "s.txt:1:13: ", "the render depth, found end of line");
    assert_parse_error("render seed", "s.txt:1:12: ", "the render seed, found end of line");
    assert_parse_error("sky gradient 1 1 1 0 0", "s.txt:1:23: ",
                       "expected a number for the blue component of the sky's top colour, found end of line");
    assert_parse_error("sky constant 1", "s.txt:1:15: ", "the green component of the sky colour");
    assert_parse_error("sky", "s.txt:1:4: ", "expected a sky type (gradient, constant, box or environment), found end of line");
    assert_parse_error("material", "s.txt:1:9: ", "expected a material name after material, found end of line");
    assert_parse_error("material m", "s.txt:1:11: ", "expected a material type");
    assert_parse_error("material m lambertian 1 1", "s.txt:1:26: ", "the blue component of material 'm', found end of line");
    assert_parse_error("material m metal 1 1 1 fuzz", "s.txt:1:28: ", "the fuzz of the metal material, found end of line");
    assert_parse_error("material m dielectric", "s.txt:1:22: ",
                       "expected a number for the index of refraction of material 'm', found end of line");
    assert_parse_error("material l emissive 1 1 1 strength", "s.txt:1:35: ", "the strength of the emissive material");
    assert_parse_error("include", "s.txt:1:8: ", "expected a quoted path after include");
}

static void test_extra_tokens(void **state)
{
    (void)state;
    assert_parse_error("material m lambertian 1 1 1\nsphere 0 0 0 1 m extra", "s.txt:2:18: ",
                       "unexpected 'extra' after the sphere (expected end of line)");
    /* Statements with optional clauses name the clauses they take. */
    assert_parse_error("sky constant 1 1 1 2", "s.txt:1:20: ", "unknown sky clause '2' (expected intensity or group)");
    assert_parse_error("sky gradient 1 1 1 0 0 0 \"x\"", "s.txt:1:26: ", "unknown sky clause the string \"x\"");
    assert_parse_error("material g dielectric 1.5 2", "s.txt:1:27: ",
                       "unknown dielectric material clause '2' (expected normal_map)");
    assert_parse_error("material g lambertian 1 1 1 fuzz 0.5", "s.txt:1:29: ",
                       "unknown lambertian material clause 'fuzz' (expected normal_map, phong or specular)");
    assert_parse_error("include \"a.txt\" more", "s.txt:1:17: ", "unexpected 'more' after the included path");
}

static void test_material_names(void **state)
{
    (void)state;
    assert_parse_error("material m lambertian 1 1 1\n\nmaterial m metal 1 1 1", "s.txt:3:10: ",
                       "material 'm' is already defined at s.txt:1:10");
    assert_parse_error("material red lambertian 1 0 0\nsphere 0 0 0 1 blue", "s.txt:2:16: ",
                       "the sphere's material 'blue' is not defined");
    assert_parse_error("sphere 0 0 0 1 later\nmaterial later lambertian 1 1 1", "s.txt:1:16: ",
                       "must be defined before the spheres that use it");
    assert_parse_error("material $m lambertian 1 1 1", "s.txt:1:10: ", "expected a material name");
    assert_parse_error("material \"m\" lambertian 1 1 1", "s.txt:1:10: ", "expected a material name");
    assert_parse_error("sphere 0 0 0 1 \"m\"", "s.txt:1:16: ", "expected a material name for the sphere");

    /* SCENE_NAME_MAX - 1 bytes is the longest name. */
    char name[SCENE_NAME_MAX + 1];
    memset(name, 'n', SCENE_NAME_MAX - 1);
    name[SCENE_NAME_MAX - 1] = '\0';
    char text[512];
    snprintf(text, sizeof text, "material %s lambertian 1 1 1\nsphere 0 0 0 1 %s", name, name);
    scene s;
    parse_ok(text, NULL, &s);
    assert_string_equal(s.materials[0].name, name);
    assert_int_equal(s.spheres[0].material, 0);
    scene_free(&s);

    memset(name, 'n', SCENE_NAME_MAX);
    name[SCENE_NAME_MAX] = '\0';
    snprintf(text, sizeof text, "material %s lambertian 1 1 1", name);
    assert_parse_error(text, "s.txt:1:10: ", "is 64 bytes long; the limit is 63");
    snprintf(text, sizeof text, "sphere 0 0 0 1 %s", name);
    assert_parse_error(text, "s.txt:1:16: ", "is not defined");
}

static void test_camera_frame_is_checked_after_the_file(void **state)
{
    (void)state;
    assert_parse_error("camera from 1 2 3\ncamera fov 30 at 1 2 3", "s.txt:2:1: ",
                       "the camera's from and at are the same point (1 2 3)");
    assert_parse_error("camera from 0 0 0 at 0 -5 0\nrender spp 1\n  camera fov 20", "s.txt:3:3: ",
                       "the camera's up (0 1 0) is parallel to its view direction (0 -5 0)");
    assert_parse_error("camera up 0 0 0", "s.txt:1:1: ", "the camera's up (0 0 0) is parallel");

    /* A frame that is only bad between two statements is fine: the final one counts. */
    scene s;
    parse_ok("camera from 0 0 0 at 0 -5 0\ncamera up 1 0 0\n", NULL, &s);
    assert_vector_equal(s.camera.up, 1, 0, 0);
    scene_free(&s);
    parse_ok("camera at 0 0 1\ncamera from 0 0 5", NULL, &s);
    assert_vector_equal(s.camera.look_at, 0, 0, 1);
    scene_free(&s);
}

static void test_lexical_errors(void **state)
{
    (void)state;
    assert_parse_error("include \"abc", "s.txt:1:9: ", "unterminated string");
    assert_parse_error("camera {", "s.txt:1:8: ", "unexpected '{'");
    assert_parse_error("camera fov 30\n}", "s.txt:2:1: ", "unexpected '}'");
    assert_parse_error("sphere{", "s.txt:1:7: ", "unexpected '{'");
}

static void test_binary_bytes(void **state)
{
    (void)state;
    assert_parse_error("camera fov 30\nsky \x01", "s.txt:2:5: ", "unexpected byte 0x01");
    assert_parse_error("camera\x7f", "s.txt:1:7: ", "unexpected byte 0x7F");
    assert_parse_error("# comment \xff\n", "s.txt:1:11: ", "unexpected byte 0xFF (not valid UTF-8");
    assert_parse_error("camera \xC0\xAF", "s.txt:1:8: ", "unexpected byte 0xC0");     /* overlong */
    assert_parse_error("# \xED\xA0\x80", "s.txt:1:3: ", "unexpected byte 0xED");         /* surrogate */
    assert_parse_error("# \xF4\x90\x80\x80", "s.txt:1:3: ", "unexpected byte 0xF4");     /* > U+10FFFF */
    assert_parse_error("#\n# \xE2\x82", "s.txt:2:3: ", "unexpected byte 0xE2");          /* truncated */
    assert_parse_error("# \x80", "s.txt:1:3: ", "unexpected byte 0x80");                 /* lone continuation */
    /* A bad byte on a later line does not hide an earlier error. */
    assert_parse_error("camera fov 0\n\x01", "s.txt:1:12: ", "fov");
}

static void test_very_long_lines(void **state)
{
    (void)state;
    size_t spaces = 1000000;
    const char *head = "material m lambertian 1 1 1\nsphere";
    const char *tail = "0 0 0 2 m\ncamera fov";
    size_t length = strlen(head) + spaces + strlen(tail) + spaces + 16;
    char *text = malloc(length);
    assert_non_null(text);
    char *end = text;
    end += sprintf(end, "%s", head);
    memset(end, ' ', spaces);
    end += spaces;
    end += sprintf(end, "%s", tail);
    memset(end, '\t', spaces);
    end += spaces;
    sprintf(end, "abc");

    /* The error is on line 3 at column 11 + spaces (after "camera fov" and the tabs). */
    char prefix[64];
    snprintf(prefix, sizeof prefix, "s.txt:3:%zu: ", strlen("camera fov") + spaces + 1);
    assert_parse_error(text, prefix, "found 'abc'");

    sprintf(end, "45");
    scene s;
    parse_ok(text, NULL, &s);
    assert_int_equal(s.sphere_count, 1);
    assert_double_equal(s.spheres[0].radius, 2, 0);
    assert_double_equal(s.camera.vertical_fov_degrees, 45, 0);
    scene_free(&s);
    free(text);

    /* A long quoted token is cut in the message, which stays well inside the buffer. */
    char long_token[3000];
    memset(long_token, 'x', sizeof long_token - 1);
    long_token[sizeof long_token - 1] = '\0';
    char long_text[3100];
    snprintf(long_text, sizeof long_text, "camera fov %s", long_token);
    assert_parse_error(long_text, "s.txt:1:12: ", "found 'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...'");
    /* ... and never in the middle of a UTF-8 character (é is 2 bytes at bytes 40 and 41). */
    snprintf(long_text, sizeof long_text, "camera fov %.39s\xC3\xA9yyyy", long_token);
    assert_parse_error(long_text, "s.txt:1:12: ", "found 'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...'");
}

static void test_many_spheres(void **state)
{
    (void)state;
    int count = 20000;
    size_t size = (size_t)count * 40 + 64;
    char *text = malloc(size);
    assert_non_null(text);
    size_t used = (size_t)snprintf(text, size, "material m lambertian 1 1 1\n");
    for (int i = 0; i < count; i++)
        used += (size_t)snprintf(text + used, size - used, "sphere %d 0 0 0.5 m\n", i);
    scene s;
    parse_ok(text, NULL, &s);
    assert_int_equal(s.sphere_count, count);
    assert_double_equal(s.spheres[count - 1].center[0], count - 1, 0);
    scene_free(&s);
    free(text);
}

/* ------------------------------------------------------------------ -D defines */

static void test_define_overrides_set(void **state)
{
    (void)state;
    scene_define defines[] = {{"t", "0.5", false}, {"w", "2*pi", false}};
    scene_parse_options options = options_with_defines(defines, 2);
    scene s;
    /* The file's set of t is skipped (its expression is not even evaluated). */
    parse_ok("set t 0.25\nset t )))\nset w 1\nset other $t * 2\n"
             "material m lambertian 1 1 1\nsphere 0 0 0 $t m\nsphere $w $other 0 1 m\n", &options, &s);
    assert_double_equal(s.spheres[0].radius, 0.5, 0);
    assert_double_equal(s.spheres[1].center[0], 2 * 3.14159265358979, 1e-5);
    assert_double_equal(s.spheres[1].center[1], 1, 0);
    scene_free(&s);

    /* Without the define the file's value is used. */
    parse_ok("set t 0.25\nmaterial m lambertian 1 1 1\nsphere 0 0 0 $t m\n", NULL, &s);
    assert_double_equal(s.spheres[0].radius, 0.25, 0);
    scene_free(&s);
}

static void test_define_used_without_set(void **state)
{
    (void)state;
    scene_define defines[] = {{"r", "3", false}, {"r", "4", false}};   /* the later of two defines wins */
    scene_parse_options options = options_with_defines(defines, 2);
    scene s;
    parse_ok("material m lambertian 1 1 1\nsphere 0 0 0 $r m", &options, &s);
    assert_double_equal(s.spheres[0].radius, 4, 0);
    scene_free(&s);
}

static void test_define_unused_is_an_error(void **state)
{
    (void)state;
    scene_define defines[] = {{"t", "1", false}, {"foo", "2", false}};
    scene_parse_options options = options_with_defines(defines, 2);
    scene s;
    rt_error error = {{0}};
    assert_int_equal(scene_load_string("set t 0\n", "s.txt", &options, &s, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "-D foo: the scene never sets or uses $foo");
    assert_true(scene_is_default(&s));

    /* Setting it counts as a mention even if nothing uses it afterwards. */
    scene_define set_only[] = {{"foo", "2", false}};
    options = options_with_defines(set_only, 1);
    parse_ok("set foo 1\n", &options, &s);
    scene_free(&s);

    /* A define named only in the skipped `set` of another define is still used. */
    scene_define chained[] = {{"a", "1", false}, {"b", "2", false}, {"bc", "3", false}};
    options = options_with_defines(chained, 3);
    parse_ok("set a $b + $bc*2\nmaterial m lambertian 1 1 1\nsphere 0 0 0 $a m\n", &options, &s);
    assert_double_equal(s.spheres[0].radius, 1, 0);
    scene_free(&s);
    options = options_with_defines(chained, 3);
    assert_parse_error_with("set a $b\n", &options, "-D bc: ", "the scene never sets or uses $bc");
}

static void test_define_bad_value(void **state)
{
    (void)state;
    scene_define bad_value[] = {{"t", "abc", false}};
    scene_parse_options options = options_with_defines(bad_value, 1);
    assert_parse_error_with("set t 1", &options, "-D t=abc: column 3: ", "unknown name 'abc'");

    scene_define bad_expression[] = {{"t", "1/0", false}};
    options = options_with_defines(bad_expression, 1);
    assert_parse_error_with("set t 1", &options, "-D t=1/0: column 4: ", "division by zero");

    scene_define empty[] = {{"t", "", false}};
    options = options_with_defines(empty, 1);
    assert_parse_error_with("set t 1", &options, "-D t=: ", "empty expression");

    scene_define uses_variable[] = {{"t", "$u", false}};
    options = options_with_defines(uses_variable, 1);
    assert_parse_error_with("set t 1", &options, "-D t=$u: column 3: ", "variables cannot be used here");

    scene_define bad_name[] = {{"1x", "2", false}};
    options = options_with_defines(bad_name, 1);
    assert_parse_error_with("set t 1", &options, "-D 1x=2: ", "'1x' is not a valid variable name");

    scene_define missing_value[] = {{"t", NULL, false}};
    options = options_with_defines(missing_value, 1);
    assert_parse_error_with("set t 1", &options, "-D t: ", "missing value");
}

/* ------------------------------------------------------------------ files and includes */

static void test_load_file(void **state)
{
    write_text(state, "scene.txt", "render spp 3\nmaterial m metal 1 1 1 fuzz 0.5\nsphere 0 0 0 1 m\n");
    scene s;
    load_file_ok(state, "scene.txt", NULL, &s);
    assert_int_equal(s.render.samples_per_pixel, 3);
    assert_int_equal(s.sphere_count, 1);
    scene_free(&s);

    write_text(state, "empty.txt", "");
    load_file_ok(state, "empty.txt", NULL, &s);
    assert_true(scene_is_default(&s));
    scene_free(&s);

    write_text(state, "bad.txt", "render spp 3\n\nsphere 0 0 0 1 m\n");
    assert_file_error(state, "bad.txt", NULL, "%s/bad.txt:3:16: ", "the sphere's material 'm' is not defined");
}

static void test_unreadable_top_file(void **state)
{
    const char *directory = ((scratch *)*state)->directory;
    char path[256], expected[512];
    scene s;
    rt_error error = {{0}};

    path_in(state, "missing.txt", path, sizeof path);
    assert_int_equal(scene_load_file(path, NULL, &s, &error), RT_ERROR_INPUT);
    snprintf(expected, sizeof expected, "SCENE: cannot read '%s/missing.txt': No such file or directory", directory);
    assert_string_equal(error.message, expected);
    assert_true(scene_is_default(&s));

    assert_int_equal(scene_load_file(directory, NULL, &s, &error), RT_ERROR_INPUT);
    snprintf(expected, sizeof expected, "SCENE: cannot read '%s': Is a directory", directory);
    assert_string_equal(error.message, expected);
    assert_true(scene_is_default(&s));
}

static void test_binary_file(void **state)
{
    write_bytes(state, "nul.txt", "camera fov 30\ncamera\0fov", 24);
    assert_file_error(state, "nul.txt", NULL, "%s/nul.txt:2:7: ", "unexpected byte 0x00");

    static const char png_header[] = "\x89PNG\r\n\x1a\n\0\0\0\rIHDR";
    write_bytes(state, "image.png", png_header, sizeof png_header - 1);
    assert_file_error(state, "image.png", NULL, "%s/image.png:1:1: ", "unexpected byte 0x89");
}

static void test_include_relative_to_including_file(void **state)
{
    write_text(state, "top.txt", "set size 3\ninclude \"sub/materials.txt\"\nsphere 0 0 0 $radius ground\n");
    write_text(state, "sub/materials.txt", "material ground lambertian 0.5 0.5 0.5\ninclude \"more.txt\"\n");
    /* more.txt is found next to materials.txt (sub/), not next to top.txt */
    write_text(state, "sub/more.txt", "set radius $size * 2   # variables are global across includes\n");
    write_text(state, "more.txt", "this file must not be read\n");
    scene s;
    load_file_ok(state, "top.txt", NULL, &s);
    assert_int_equal(s.material_count, 1);
    assert_int_equal(s.sphere_count, 1);
    assert_double_equal(s.spheres[0].radius, 6, 0);
    scene_free(&s);

    /* An error in an include is reported at its resolved path. */
    write_text(state, "sub/broken.txt", "\n  sphere 0 0 0 -1 m\n");
    write_text(state, "top2.txt", "material m lambertian 1 1 1\ninclude \"sub/broken.txt\"\n");
    assert_file_error(state, "top2.txt", NULL, "%s/sub/broken.txt:2:16: ", "the sphere's radius must be > 0");

    /* A duplicate material names the file of the first definition. */
    write_text(state, "dup.txt", "set size 1\ninclude \"sub/materials.txt\"\nmaterial ground metal 1 1 1\n");
    assert_file_error(state, "dup.txt", NULL, "%s/dup.txt:3:10: ",
                      "material 'ground' is already defined at %s/sub/materials.txt:1:10");
}

static void test_include_from_string_and_absolute_path(void **state)
{
    const char *directory = ((scratch *)*state)->directory;
    write_text(state, "m.txt", "material m lambertian 1 1 1\n");
    char source_name[256], text[512];
    snprintf(source_name, sizeof source_name, "%s/virtual.txt", directory);
    scene s;
    check_parse_ok("include \"m.txt\"\nsphere 0 0 0 1 m", source_name, NULL, &s, __FILE__, __LINE__);
    assert_int_equal(s.sphere_count, 1);
    scene_free(&s);

    snprintf(text, sizeof text, "include \"%s/m.txt\"\nsphere 0 0 0 1 m", directory);
    check_parse_ok(text, "elsewhere/x.txt", NULL, &s, __FILE__, __LINE__);
    assert_int_equal(s.material_count, 1);
    scene_free(&s);
}

static void test_include_camera_position(void **state)
{
    /* The camera frame error names the last camera statement, wherever it is. */
    write_text(state, "cam.txt", "# camera\n    camera at 0 0 1\n");
    write_text(state, "top.txt", "camera from 0 0 1\ninclude \"cam.txt\"\n");
    assert_file_error(state, "top.txt", NULL, "%s/cam.txt:2:5: ", "the camera's from and at are the same point");
}

static void test_missing_include(void **state)
{
    write_text(state, "top.txt", "render spp 1\n  include \"nope/missing.txt\"\n");
    assert_file_error(state, "top.txt", NULL, "%s/top.txt:2:3: ",
                      "cannot read included file '%s/nope/missing.txt': No such file or directory");

    mkdir(path_in(state, "folder", (char[256]){0}, 256), 0700);
    write_text(state, "dir.txt", "include \"folder\"\n");
    assert_file_error(state, "dir.txt", NULL, "%s/dir.txt:1:1: ", "cannot read included file '%s/folder': Is a directory");

    write_text(state, "empty-path.txt", "include \"\"\n");
    assert_file_error(state, "empty-path.txt", NULL, "%s/empty-path.txt:1:9: ", "found an empty string");

    write_text(state, "unquoted.txt", "include other.txt\n");
    assert_file_error(state, "unquoted.txt", NULL, "%s/unquoted.txt:1:9: ",
                      "expected a quoted path after include (e.g. include \"common.txt\"), found 'other.txt'");
}

/* A file that never ends (a device) or is absurdly large fails with a message instead
 * of being read until memory runs out. The large one is sparse: it takes no disk space. */
static void test_oversized_files(void **state)
{
    write_text(state, "zero.txt", "include \"/dev/zero\"\n");
    assert_file_error(state, "zero.txt", NULL, "%s/zero.txt:1:1: ",
                      "cannot read included file '/dev/zero': File too large");

    const char *directory = ((scratch *)*state)->directory;
    char path[256], expected[512];
    write_text(state, "huge.txt", "");
    assert_int_equal(truncate(path_in(state, "huge.txt", path, sizeof path), (off_t)300 << 20), 0);
    scene s;
    rt_error error = {{0}};
    assert_int_equal(scene_load_file(path, NULL, &s, &error), RT_ERROR_INPUT);
    snprintf(expected, sizeof expected, "SCENE: cannot read '%s/huge.txt': File too large", directory);
    assert_string_equal(error.message, expected);
    assert_true(scene_is_default(&s));
}

static void test_include_cycles(void **state)
{
    write_text(state, "a.txt", "include \"b.txt\"\n");
    write_text(state, "b.txt", "# b\ninclude \"a.txt\"\n");
    assert_file_error(state, "a.txt", NULL, "%s/b.txt:2:1: ", "include cycle: %s/a.txt -> %s/b.txt -> %s/a.txt");

    write_text(state, "self.txt", "render spp 1\ninclude \"self.txt\"\n");
    assert_file_error(state, "self.txt", NULL, "%s/self.txt:2:1: ", "include cycle: %s/self.txt -> %s/self.txt");

    /* Files are compared by identity, not by spelling. */
    write_text(state, "dot.txt", "include \"./dot.txt\"\n");
    assert_file_error(state, "dot.txt", NULL, "%s/dot.txt:1:1: ", "include cycle: %s/dot.txt -> %s/./dot.txt");

    /* Including the same file twice, one after the other, is not a cycle. */
    write_text(state, "settings.txt", "render spp 5\n");
    write_text(state, "twice.txt", "include \"settings.txt\"\ninclude \"settings.txt\"\n");
    scene s;
    load_file_ok(state, "twice.txt", NULL, &s);
    assert_int_equal(s.render.samples_per_pixel, 5);
    scene_free(&s);
}

/* Writes level0.txt .. level<count>.txt, each including the next; the last sets spp. */
static void write_include_chain(void **state, int count)
{
    for (int i = 0; i < count; i++) {
        char name[32], content[64];
        snprintf(name, sizeof name, "level%d.txt", i);
        snprintf(content, sizeof content, "include \"level%d.txt\"\n", i + 1);
        write_text(state, name, content);
    }
    char name[32];
    snprintf(name, sizeof name, "level%d.txt", count);
    write_text(state, name, "render spp 9\n");
}

static void test_include_depth_limit(void **state)
{
    /* level0 -> ... -> level16: 16 levels of include, the default limit. */
    write_include_chain(state, 16);
    scene s;
    load_file_ok(state, "level0.txt", NULL, &s);
    assert_int_equal(s.render.samples_per_pixel, 9);
    scene_free(&s);

    write_include_chain(state, 17);
    assert_file_error(state, "level0.txt", NULL, "%s/level16.txt:1:1: ",
                      "includes nested too deeply: '%s/level17.txt' would be level 17, the limit is 16");

    scene_parse_options options = scene_parse_options_defaults();
    options.max_include_depth = 2;
    assert_file_error(state, "level0.txt", &options, "%s/level2.txt:1:1: ", "would be level 3, the limit is 2");
    options.max_include_depth = 30;
    load_file_ok(state, "level0.txt", &options, &s);
    assert_int_equal(s.render.samples_per_pixel, 9);
    scene_free(&s);
}

static void test_define_applies_across_includes(void **state)
{
    write_text(state, "vars.txt", "set radius 1\n");
    write_text(state, "top.txt", "include \"vars.txt\"\nmaterial m lambertian 1 1 1\nsphere 0 0 0 $radius m\n");
    scene_define defines[] = {{"radius", "0.1 * 7", false}};
    scene_parse_options options = options_with_defines(defines, 1);
    scene s;
    load_file_ok(state, "top.txt", &options, &s);
    assert_double_equal(s.spheres[0].radius, 0.7, 1e-7);
    scene_free(&s);
}

/* ------------------------------------------------------------------ full example */

static void test_documented_example(void **state)
{
    (void)state;
    /* The complete example of docs/scene-format.md, kept in sync by hand. */
    const char *text =
        "# A glass ball, a diffuse ball and a metal ball on a huge ground sphere.\n"
        "set t 0                                  # animation time, sweep with -D t=...\n"
        "set angle 2*pi*$t\n"
        "\n"
        "render size 640 360 spp 64 depth 16 seed 7\n"
        "camera from (4*cos($angle)) 1.5 (4*sin($angle)) at 0 0.5 0 up 0 1 0 fov 40\n"
        "camera aperture 0.05 focus 4\n"
        "sky gradient 1 1 1  0.5 0.7 1.0\n"
        "\n"
        "material ground lambertian 0.5 0.5 0.5\n"
        "material red lambertian 0.8 0.2 0.1\n"
        "material glass dielectric 1.5\n"
        "material gold metal 0.9 0.7 0.3 fuzz 0.1\n"
        "material lamp emissive 1 0.9 0.8 strength 10\n"
        "\n"
        "sphere 0 -1000 0 1000 ground\n"
        "sphere -1.2 0.5 0 0.5 red\n"
        "sphere 0 0.5 0 0.5 glass\n"
        "sphere 1.2 0.5 0 0.5 gold\n"
        "sphere 0 5 0 1 lamp\n";
    scene_define defines[] = {{"t", "0.25", false}};
    scene_parse_options options = options_with_defines(defines, 1);
    scene s;
    parse_ok(text, &options, &s);
    assert_int_equal(s.material_count, 5);
    assert_int_equal(s.sphere_count, 5);
    assert_vector_equal(s.camera.look_from, 0, 1.5, 4);
    assert_double_equal(s.camera.aperture, 0.05, 1e-7);
    assert_vector_equal(s.materials[4].emission, 10, 9, 8);
    assert_int_equal(s.spheres[4].material, 4);
    scene_free(&s);
}

/* ------------------------------------------------------------------ the scene model: helpers */

/* Maps the point (x, y, z) through an instance's object_to_world into out. */
static void map_point(const scene_instance *instance, double x, double y, double z, double out[3])
{
    const float (*m)[4] = instance->object_to_world;
    for (int row = 0; row < 3; row++)
        out[row] = m[row][0] * x + m[row][1] * y + m[row][2] * z + m[row][3];
}

/* Checks that instance maps (x, y, z) to (ex, ey, ez) within float rounding. */
#define assert_maps(instance, x, y, z, ex, ey, ez)                  \
    do {                                                            \
        double mapped_[3];                                          \
        map_point((instance), (x), (y), (z), mapped_);              \
        assert_double_equal(mapped_[0], (ex), 1e-4);                \
        assert_double_equal(mapped_[1], (ey), 1e-4);                \
        assert_double_equal(mapped_[2], (ez), 1e-4);                \
    } while (0)

/* True when the instance's transform is exactly the identity. */
static bool is_identity(const scene_instance *instance)
{
    for (int row = 0; row < 3; row++)
        for (int column = 0; column < 4; column++)
            if (instance->object_to_world[row][column] != (row == column ? 1.0f : 0.0f))
                return false;
    return true;
}

/* ------------------------------------------------------------------ textures, materials, sky, camera */

static void test_textures(void **state)
{
    (void)state;
    scene s;
    parse_ok("texture white constant 1 1 1\n"
             "texture checks checker 0.5 0.1 0.2 0.3 @white\n"
             "texture grain noise 4\n"
             "texture swirl turbulence (2*2)\n"
             "texture stone marble 0.25\n"
             "texture wood image \"img/wood.png\"\n"
             "texture nested checker 2 @checks @grain\n"
             "texture same constant @white   # another name for white\n"
             "texture wood2 image \"img/wood.png\"\n", NULL, &s);
    /* The checker's plain colour is a hidden texture (empty name) just before it. */
    assert_int_equal(s.texture_count, 10);
    assert_string_equal(s.textures[0].name, "white");
    assert_int_equal(s.textures[0].type, TEXTURE_CONSTANT);
    assert_vector_equal(s.textures[0].color, 1, 1, 1);
    assert_string_equal(s.textures[1].name, "");
    assert_int_equal(s.textures[1].type, TEXTURE_CONSTANT);
    assert_vector_equal(s.textures[1].color, 0.1, 0.2, 0.3);
    assert_string_equal(s.textures[2].name, "checks");
    assert_int_equal(s.textures[2].type, TEXTURE_CHECKER);
    assert_double_equal(s.textures[2].scale, 0.5, 0);
    assert_int_equal(s.textures[2].even, 1);
    assert_int_equal(s.textures[2].odd, 0);
    assert_int_equal(s.textures[3].type, TEXTURE_NOISE);
    assert_double_equal(s.textures[3].scale, 4, 0);
    assert_int_equal(s.textures[4].type, TEXTURE_TURBULENCE);
    assert_double_equal(s.textures[4].scale, 4, 0);
    assert_int_equal(s.textures[5].type, TEXTURE_MARBLE);
    assert_int_equal(s.textures[6].type, TEXTURE_IMAGE);
    assert_int_equal(s.textures[6].image, 0);
    assert_int_equal(s.textures[7].even, 2);
    assert_int_equal(s.textures[7].odd, 3);
    assert_string_equal(s.textures[8].name, "same");
    assert_int_equal(s.textures[8].type, TEXTURE_CONSTANT);
    assert_vector_equal(s.textures[8].color, 1, 1, 1);
    assert_int_equal(s.textures[9].image, 0);                  /* one image per path */
    assert_int_equal(s.image_count, 1);
    assert_string_equal(s.images[0].path, "img/wood.png");
    assert_string_equal(s.images[0].position, "s.txt:6:20");
    assert_null(s.images[0].pixels);
    assert_int_equal(s.material_count, 0);
    scene_free(&s);

    /* Texture names are their own namespace: a material may have the same name. */
    parse_ok("texture red constant 1 0 0\nmaterial red lambertian @red\n", NULL, &s);
    assert_int_equal(s.materials[0].albedo_texture, 0);
    scene_free(&s);
}

static void test_texture_errors(void **state)
{
    (void)state;
    assert_parse_error("texture a constant 1 1 1\n\ntexture a noise 1", "s.txt:3:9: ",
                       "texture 'a' is already defined at s.txt:1:9");
    assert_parse_error("texture c checker 1 @nope 0 0 0", "s.txt:1:21: ",
                       "texture 'nope' is not defined (a texture must be defined before it is used)");
    assert_parse_error("texture c checker 1 0 0 0 @later\ntexture later constant 1 1 1", "s.txt:1:27: ",
                       "texture 'later' is not defined");
    assert_parse_error("material m lambertian @missing", "s.txt:1:23: ", "texture 'missing' is not defined");
    assert_parse_error("material m emissive @missing strength 2", "s.txt:1:21: ", "texture 'missing' is not defined");
    assert_parse_error("material m lambertian @", "s.txt:1:23: ", "expected a texture reference @NAME, found '@'");
    assert_parse_error("texture c checker 0 1 1 1 0 0 0", "s.txt:1:19: ",
                       "the scale of texture 'c' must be > 0, found 0");
    assert_parse_error("texture n noise -1", "s.txt:1:17: ", "the scale of texture 'n' must be > 0, found -1");
    assert_parse_error("texture n turbulence 0", "s.txt:1:22: ", "must be > 0");
    assert_parse_error("texture n marble 1e-50", "s.txt:1:18: ", "too small for the renderer's 32-bit floats");
    assert_parse_error("texture i image \"\"", "s.txt:1:17: ",
                       "expected a path inside the quotes of the image of texture 'i', found an empty string");
    assert_parse_error("texture i image wood.png", "s.txt:1:17: ", "expected a quoted path for the image of texture 'i'");
    assert_parse_error("texture x wavy 1", "s.txt:1:11: ",
                       "expected a texture type (constant, checker, noise, turbulence, marble or image), found 'wavy'");
    assert_parse_error("texture", "s.txt:1:8: ", "expected a texture name after texture, found end of line");
    assert_parse_error("texture $t constant 1 1 1", "s.txt:1:9: ", "expected a texture name");
    assert_parse_error("texture k constant 1 -1 1", "s.txt:1:22: ",
                       "the green component of texture 'k' must be >= 0");
    assert_parse_error("texture k checker 1 1 1 1 1 1", "s.txt:1:30: ",
                       "expected a number for the blue component of the odd colour of texture 'k', found end of line");
    assert_parse_error("texture k noise 1 2", "s.txt:1:19: ", "unexpected '2' after the texture");
}

static void test_material_textures_and_normal_maps(void **state)
{
    (void)state;
    scene s;
    parse_ok("texture grain noise 3\n"
             "texture glow constant 1 0.5 0\n"
             "material plain lambertian 0.5 0.5 0.5\n"
             "material wood lambertian @grain normal_map \"maps/n.png\"\n"
             "material brushed metal @grain fuzz 0.25 normal_map \"maps/n.png\"\n"
             "material shiny metal 0.9 0.9 0.9 normal_map \"maps/m.png\" fuzz 0.5\n"
             "material glass dielectric 1.5 normal_map \"maps/m.png\"\n"
             "material lamp emissive @glow strength 3\n", NULL, &s);
    assert_int_equal(s.material_count, 6);
    /* Plain materials have no textures. */
    assert_int_equal(s.materials[0].albedo_texture, -1);
    assert_int_equal(s.materials[0].emission_texture, -1);
    assert_int_equal(s.materials[0].normal_map, -1);
    /* A texture colour leaves the albedo at 1 1 1. */
    assert_int_equal(s.materials[1].albedo_texture, 0);
    assert_vector_equal(s.materials[1].albedo, 1, 1, 1);
    assert_int_equal(s.materials[1].normal_map, 0);
    assert_int_equal(s.materials[2].type, MATERIAL_METAL);
    assert_int_equal(s.materials[2].albedo_texture, 0);
    assert_double_equal(s.materials[2].fuzz, 0.25, 0);
    assert_int_equal(s.materials[2].normal_map, 0);           /* same path, same image */
    assert_int_equal(s.materials[3].albedo_texture, -1);
    assert_double_equal(s.materials[3].fuzz, 0.5, 0);
    assert_int_equal(s.materials[3].normal_map, 1);
    assert_int_equal(s.materials[4].normal_map, 1);
    assert_double_equal(s.materials[4].index_of_refraction, 1.5, 0);
    /* emissive @texture: emission is 1 1 1 x strength, times the texture. */
    assert_int_equal(s.materials[5].emission_texture, 1);
    assert_int_equal(s.materials[5].albedo_texture, -1);
    assert_vector_equal(s.materials[5].emission, 3, 3, 3);
    assert_int_equal(s.image_count, 2);
    assert_string_equal(s.images[0].path, "maps/n.png");
    assert_string_equal(s.images[0].position, "s.txt:4:44");
    assert_string_equal(s.images[1].position, "s.txt:6:45");
    scene_free(&s);

    assert_parse_error("material m lambertian 1 1 1 normal_map \"\"", "s.txt:1:40: ",
                       "expected a path inside the quotes of the normal_map of the lambertian material, found an "
                       "empty string");
    assert_parse_error("material m metal 1 1 1 normal_map", "s.txt:1:34: ",
                       "expected a quoted path for the normal_map of the metal material");
    assert_parse_error("material m dielectric 1.5 normal_map \"a.png\" normal_map \"b.png\"", "s.txt:1:46: ",
                       "clause 'normal_map' given twice");
    assert_parse_error("material m emissive 1 1 1 normal_map \"a.png\"", "s.txt:1:27: ",
                       "unknown emissive material clause 'normal_map' (expected strength, one_sided or group)");
}

/* The pbr material: every clause, the defaults (ior 1.5, opaque, no emission), emission
 * as colour x strength, maps as data images, and its errors. */
static void test_pbr_material(void **state)
{
    (void)state;
    scene s;
    parse_ok("texture base image \"maps/base.png\"\n"
             "material plain pbr 0.8 0.6 0.4 metallic 0 roughness 0.5\n"
             "material all pbr @base roughness 0.25 metallic 1 ior 1.33 transmission 0.75 emission 1 0.5 0.25 "
             "strength 4 one_sided alpha 0.5 alpha_cutoff 0.25 vertex_colors normal_map \"maps/n.png\" "
             "metallic_roughness_map \"maps/mr.png\"\n"
             "material glow pbr 1 1 1 metallic 0 roughness 1 emission @base\n"
             "material cut pbr 1 1 1 metallic 0 roughness 1 alpha_cutoff 0.3\n"
             "material lamp emissive 1 1 1 one_sided\n", NULL, &s);
    assert_int_equal(s.material_count, 5);
    const scene_material *plain = &s.materials[0], *all = &s.materials[1];
    assert_int_equal(plain->type, MATERIAL_PBR);
    assert_vector_equal(plain->albedo, 0.8, 0.6, 0.4);
    assert_double_equal(plain->metallic, 0, 0);
    assert_double_equal(plain->roughness, 0.5, 0);
    assert_double_equal(plain->index_of_refraction, 1.5, 0);
    assert_double_equal(plain->transmission, 0, 0);
    assert_vector_equal(plain->emission, 0, 0, 0);
    assert_int_equal(plain->alpha_mode, SCENE_ALPHA_OPAQUE);
    assert_double_equal(plain->alpha, 1, 0);
    assert_false(plain->one_sided || plain->vertex_colors);
    assert_int_equal(plain->albedo_texture, -1);
    assert_int_equal(plain->metallic_roughness_texture, -1);
    assert_int_equal(plain->normal_map, -1);

    assert_int_equal(all->albedo_texture, 0);
    assert_vector_equal(all->albedo, 1, 1, 1);
    assert_double_equal(all->metallic, 1, 0);
    assert_double_equal(all->roughness, 0.25, 0);
    assert_double_equal(all->index_of_refraction, 1.33, 1e-6);
    assert_double_equal(all->transmission, 0.75, 0);
    assert_vector_equal(all->emission, 4, 2, 1);
    assert_true(all->one_sided && all->vertex_colors);
    assert_int_equal(all->alpha_mode, SCENE_ALPHA_MASK);
    assert_double_equal(all->alpha, 0.5, 0);
    assert_double_equal(all->alpha_cutoff, 0.25, 0);
    assert_int_equal(s.image_count, 3);
    assert_int_equal(all->normal_map, 1);
    assert_int_equal(all->metallic_roughness_texture, 2);
    assert_false(s.images[0].data);                 /* the base colour: sRGB-decoded */
    assert_true(s.images[1].data && s.images[2].data);
    assert_string_equal(s.images[2].path, "maps/mr.png");

    assert_int_equal(s.materials[2].emission_texture, 0);    /* emission @texture, strength 1 */
    assert_vector_equal(s.materials[2].emission, 1, 1, 1);
    assert_int_equal(s.materials[3].alpha_mode, SCENE_ALPHA_MASK);   /* the cutoff alone masks */
    assert_double_equal(s.materials[3].alpha_cutoff, 0.3, 1e-7);
    assert_double_equal(s.materials[3].alpha, 1, 0);
    assert_int_equal(s.materials[4].type, MATERIAL_EMISSIVE);
    assert_true(s.materials[4].one_sided);
    scene_free(&s);

    assert_parse_error("material m pbr 1 1 1 metallic 0", "s.txt:1:12: ",
                       "the pbr material 'm' needs metallic M and roughness R, each from 0 to 1");
    assert_parse_error("material m pbr 1 1 1 roughness 0", "s.txt:1:12: ", "needs metallic M and roughness R");
    assert_parse_error("material m pbr 1 1 1 metallic 1.5 roughness 0", "s.txt:1:31: ",
                       "the metallic of material 'm' must be between 0 and 1, found 1.5");
    assert_parse_error("material m pbr 1 1 1 metallic 0 roughness -0.1", "s.txt:1:43: ",
                       "the roughness of material 'm' must be between 0 and 1, found -0.1");
    assert_parse_error("material m pbr 1 1 1 metallic 0 roughness 0 ior 0", "s.txt:1:49: ", "the ior of material 'm' must be > 0, found 0");
    assert_parse_error("material m pbr 1 1 1 metallic 0 roughness 0 strength -1", "s.txt:1:54: ",
                       "the strength of material 'm' must be >= 0, found -1");
    assert_parse_error("material m pbr 1 1 1 metallic 0 roughness 0 fuzz 1", "s.txt:1:45: ",
                       "unknown pbr material clause 'fuzz' (expected metallic, roughness, ior, transmission, "
                       "emission, strength, one_sided, alpha, alpha_cutoff, vertex_colors, normal_map, "
                       "metallic_roughness_map or group)");
    assert_parse_error("material m pbr 1 1 1 metallic 0 roughness 0 metallic 1", "s.txt:1:45: ",
                       "pbr material clause 'metallic' given twice");
    assert_parse_error("material m pbr 1 1 1 metallic 0 roughness 0 emission @nothing", "s.txt:1:54: ",
                       "texture 'nothing' is not defined");
    assert_parse_error("material m pbr 1 1 1 metallic 0 roughness 0 normal_map", "s.txt:1:55: ",
                       "expected a quoted path for the normal_map of the pbr material");
    assert_parse_error("material m pbr 1 1 metallic 0 roughness 0", "s.txt:1:20: ",
                       "the blue component of material 'm'");
    assert_parse_error("material m metal 1 1 1 one_sided", "s.txt:1:24: ", "unknown metal material clause 'one_sided'");
}

static void test_sky_images_intensity_and_rotation(void **state)
{
    (void)state;
    scene s;
    parse_ok("sky gradient 0 0 0 1 1 1 intensity 2.5", NULL, &s);
    assert_int_equal(s.sky.type, SKY_GRADIENT);
    assert_double_equal(s.sky.intensity, 2.5, 0);
    assert_double_equal(s.sky.rotation_degrees, 0, 0);
    assert_int_equal(s.sky.environment, -1);
    assert_int_equal(s.sky.faces[0], -1);
    scene_free(&s);

    parse_ok("sky constant 1 2 3 intensity 0", NULL, &s);
    assert_int_equal(s.sky.type, SKY_CONSTANT);
    assert_double_equal(s.sky.intensity, 0, 0);
    scene_free(&s);

    parse_ok("texture t image \"sky/py.png\"\n"
             "sky box \"sky/px.png\" \"sky/nx.png\" \"sky/py.png\" \"sky/ny.png\" \"sky/pz.png\" \"sky/nz.png\" "
             "rotate 90 intensity 0.5\n", NULL, &s);
    assert_int_equal(s.sky.type, SKY_BOX);
    assert_int_equal(s.image_count, 6);
    assert_int_equal(s.sky.faces[SKY_FACE_POSITIVE_X], 1);
    assert_int_equal(s.sky.faces[SKY_FACE_NEGATIVE_X], 2);
    assert_int_equal(s.sky.faces[SKY_FACE_POSITIVE_Y], 0);    /* shared with the texture */
    assert_int_equal(s.sky.faces[SKY_FACE_NEGATIVE_Y], 3);
    assert_int_equal(s.sky.faces[SKY_FACE_POSITIVE_Z], 4);
    assert_int_equal(s.sky.faces[SKY_FACE_NEGATIVE_Z], 5);
    assert_string_equal(s.images[5].path, "sky/nz.png");
    assert_double_equal(s.sky.intensity, 0.5, 0);
    assert_double_equal(s.sky.rotation_degrees, 90, 0);
    assert_int_equal(s.sky.environment, -1);
    scene_free(&s);

    /* A later sky replaces all of an earlier one. */
    parse_ok("sky environment \"studio.hdr\" intensity 2 rotate -45\nsky environment \"other.hdr\"", NULL, &s);
    assert_int_equal(s.sky.type, SKY_ENVIRONMENT);
    assert_int_equal(s.sky.environment, 1);
    assert_double_equal(s.sky.intensity, 1, 0);
    assert_double_equal(s.sky.rotation_degrees, 0, 0);
    assert_string_equal(s.images[0].path, "studio.hdr");
    scene_free(&s);
    parse_ok("sky environment \"studio.hdr\"\nsky gradient 1 1 1 0 0 0", NULL, &s);
    assert_int_equal(s.sky.environment, -1);
    scene_free(&s);

    assert_parse_error("sky constant 1 1 1 intensity -1", "s.txt:1:30: ", "the sky's intensity must be >= 0, found -1");
    assert_parse_error("sky environment \"e.hdr\" intensity -0.5", "s.txt:1:35: ", "intensity must be >= 0");
    assert_parse_error("sky environment \"\"", "s.txt:1:17: ",
                       "expected a path inside the quotes of the sky environment, found an empty string");
    assert_parse_error("sky environment", "s.txt:1:16: ", "expected a quoted path for the sky environment");
    assert_parse_error("sky box \"a\" \"b\" \"c\" \"\" \"e\" \"f\"", "s.txt:1:21: ",
                       "expected a path inside the quotes of the sky box's -Y face, found an empty string");
    assert_parse_error("sky box \"a\" \"b\" \"c\" \"d\" \"e\"", "s.txt:1:28: ",
                       "expected a quoted path for the sky box's -Z face (e.g. \"file.png\"), found end of line");
    assert_parse_error("sky gradient 1 1 1 1 1 1 rotate 5", "s.txt:1:26: ", "unknown sky clause 'rotate'");
    assert_parse_error("sky environment \"e.hdr\" rotate 1 rotate 2", "s.txt:1:34: ", "clause 'rotate' given twice");
}

static void test_camera_shutter(void **state)
{
    (void)state;
    scene s;
    parse_ok("", NULL, &s);
    assert_double_equal(s.camera.shutter_open, 0, 0);
    assert_double_equal(s.camera.shutter_close, 1, 0);
    scene_free(&s);
    parse_ok("camera fov 30 shutter 0.25 0.75", NULL, &s);
    assert_double_equal(s.camera.shutter_open, 0.25, 0);
    assert_double_equal(s.camera.shutter_close, 0.75, 0);
    scene_free(&s);
    parse_ok("camera shutter 0.5 0.5", NULL, &s);                  /* open == close: no blur */
    assert_double_equal(s.camera.shutter_close, 0.5, 0);
    scene_free(&s);

    assert_parse_error("camera shutter -0.1 1", "s.txt:1:16: ",
                       "the camera's shutter must have 0 <= open <= close <= 1, found open -0.1 and close 1");
    assert_parse_error("camera shutter 0.6 0.4", "s.txt:1:20: ", "found open 0.6 and close 0.4");
    assert_parse_error("camera shutter 0 1.5", "s.txt:1:18: ", "0 <= open <= close <= 1");
    assert_parse_error("camera shutter 1.5 2", "s.txt:1:16: ", "0 <= open <= close <= 1");
    assert_parse_error("camera shutter 0", "s.txt:1:17: ",
                       "expected a number for the camera's shutter close time, found end of line");
}

/* ------------------------------------------------------------------ shapes */

static void test_top_level_shapes_form_one_world_object(void **state)
{
    (void)state;
    scene s;
    parse_ok("material m lambertian 1 1 1\n"
             "material n metal 1 1 1\n"
             "sphere 0 0 0 1 m                 # a plain sphere, as in the first version\n"
             "triangle 0 0 0  1 0 0  0 1 0 m\n"
             "moving_sphere 0 0 0  0 1 0  0.5 n\n"
             "quad 0 0 0  2 0 0  0 0 3 n\n"
             "sphere 5 0 0 2 n\n", NULL, &s);
    assert_int_equal(s.sphere_count, 2);
    assert_vector_equal(s.spheres[1].center, 5, 0, 0);
    assert_int_equal(s.spheres[1].material, 1);
    assert_int_equal(s.object_count, 1);
    assert_int_equal(s.instance_count, 1);
    assert_int_equal(s.instances[0].object, 0);
    assert_int_equal(s.instances[0].material, -1);
    assert_false(s.instances[0].volume);
    assert_true(is_identity(&s.instances[0]));
    assert_int_equal(s.objects[0].first_shape, 0);
    assert_int_equal(s.objects[0].shape_count, 3);
    assert_int_equal(s.objects[0].mesh, -1);
    assert_int_equal(s.shape_count, 3);
    assert_int_equal(s.shapes[0].type, SHAPE_TRIANGLE);
    assert_int_equal(s.shapes[0].material, 0);
    assert_vector_equal(s.shapes[0].points[1], 1, 0, 0);
    assert_vector_equal(s.shapes[0].points[2], 0, 1, 0);
    assert_int_equal(s.shapes[1].type, SHAPE_MOVING_SPHERE);
    assert_int_equal(s.shapes[1].material, 1);
    assert_vector_equal(s.shapes[1].points[0], 0, 0, 0);
    assert_vector_equal(s.shapes[1].points[1], 0, 1, 0);
    assert_double_equal(s.shapes[1].radius, 0.5, 0);
    assert_int_equal(s.shapes[2].type, SHAPE_QUAD);
    assert_vector_equal(s.shapes[2].points[1], 2, 0, 0);
    assert_vector_equal(s.shapes[2].points[2], 0, 0, 3);
    scene_free(&s);

    /* Only spheres: nothing but the plain array, as before. */
    parse_ok("material m lambertian 1 1 1\nsphere 0 0 0 1 m\n", NULL, &s);
    assert_int_equal(s.object_count, 0);
    assert_int_equal(s.instance_count, 0);
    scene_free(&s);
}

static void test_box_expands_to_six_outward_quads(void **state)
{
    (void)state;
    scene s;
    parse_ok("material m lambertian 1 1 1\nbox -1 0 2  3 1 5 m\n", NULL, &s);
    assert_int_equal(s.shape_count, 6);
    assert_int_equal(s.objects[0].shape_count, 6);
    const double low[3] = {-1, 0, 2}, high[3] = {3, 1, 5};
    const double centre[3] = {1, 0.5, 3.5};
    /* +X -X +Y -Y +Z -Z: each quad lies on its face, covers it, and u x v points out. */
    for (int face = 0; face < 6; face++) {
        const scene_shape *quad = &s.shapes[face];
        assert_int_equal(quad->type, SHAPE_QUAD);
        assert_int_equal(quad->material, 0);
        int axis = face / 2;
        double sign = face % 2 == 0 ? 1 : -1;
        const float *q = quad->points[0], *u = quad->points[1], *v = quad->points[2];
        double normal[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        for (int i = 0; i < 3; i++) {
            double expected = i == axis ? sign * (high[(i + 1) % 3] - low[(i + 1) % 3]) *
                                              (high[(i + 2) % 3] - low[(i + 2) % 3])
                                        : 0;
            assert_double_equal(normal[i], expected, 1e-6);
            /* The quad's centre is the face's centre. */
            double quad_centre = q[i] + 0.5 * (u[i] + v[i]);
            double face_centre = i == axis ? (sign > 0 ? high[i] : low[i]) : centre[i];
            assert_double_equal(quad_centre, face_centre, 1e-6);
        }
    }
    scene_free(&s);

    assert_parse_error("material m lambertian 1 1 1\nbox 0 0 0  1 0 1 m", "s.txt:2:14: ",
                       "the box's minimum y (0) must be less than its maximum y (0)");
    assert_parse_error("material m lambertian 1 1 1\nbox 0 0 2  1 1 1 m", "s.txt:2:16: ", "the box's minimum z (2)");
    assert_parse_error("box 0 0 0  1 1", "s.txt:1:15: ",
                       "expected a number for the box's maximum corner z, found end of line");
}

static void test_shape_errors(void **state)
{
    (void)state;
    const char *m = "material m lambertian 1 1 1\n";
    char text[256];
    snprintf(text, sizeof text, "%squad 0 0 0  1 0 0  2 0 0 m", m);
    assert_parse_error(text, "s.txt:2:13: ", "the quad's edges u (1 0 0) and v (2 0 0) are parallel or zero, so it "
                       "has no area");
    snprintf(text, sizeof text, "%squad 0 0 0  0 0 0  0 1 0 m", m);
    assert_parse_error(text, "s.txt:2:13: ", "are parallel or zero");
    snprintf(text, sizeof text, "%squad 0 0 0  1 0 0  0 0 0 m", m);
    assert_parse_error(text, "s.txt:2:13: ", "are parallel or zero");
    snprintf(text, sizeof text, "%smoving_sphere 0 0 0 1 1 1 0 m", m);
    assert_parse_error(text, "s.txt:2:27: ", "the moving sphere's radius must be > 0, found 0");
    snprintf(text, sizeof text, "%sgroup {\n  sphere 0 0 0 -2\n}", m);
    assert_parse_error(text, "s.txt:3:16: ", "the sphere's radius must be > 0, found -2");
    snprintf(text, sizeof text, "%striangle 0 0 0 1 0 0 0 1 0 nope", m);
    assert_parse_error(text, "s.txt:2:28: ",
                       "the triangle's material 'nope' is not defined (a material must be defined before the "
                       "triangles that use it)");

    /* At the top level, where no group can supply one, every shape needs a material. */
    assert_parse_error("sphere 0 0 0 1", "s.txt:1:15: ", "a shape needs a material outside a group");
    assert_parse_error("triangle 0 0 0  1 0 0  0 1 0", "s.txt:1:29: ",
                       "expected a material name for the triangle, found end of line (a shape needs a material "
                       "outside a group)");
    assert_parse_error("moving_sphere 0 0 0 0 1 0 1", "s.txt:1:28: ", "needs a material outside a group");
    assert_parse_error("quad 0 0 0 1 0 0 0 1 0  # no material", "s.txt:1:23: ", "needs a material outside a group");
    assert_parse_error("box 0 0 0 1 1 1", "s.txt:1:16: ", "needs a material outside a group");
    assert_parse_error("mesh \"a.obj\"", "s.txt:1:13: ", "expected a material name for the mesh, found end of line (a "
                       "shape needs a material outside a group)");
}

/* triangle ... [normals N N N] [uvs UV UV UV] [MATERIAL]: per-corner shading data. */
static void test_triangle_normals_and_uvs(void **state)
{
    (void)state;
    scene s;
    /* The group's shapes come first in scene.shapes: a block's shapes are added when it
     * closes, the top level's at the end. */
    parse_ok("material m lambertian 1 1 1\n"
             "group material m {\n"
             "    triangle 0 0 0  1 0 0  0 1 0  normals 0 0 1  0 0 1  0 0 1\n"
             "}\n"
             "set n 2\n"
             "triangle 0 0 0  1 0 0  0 1 0  normals 0 0 $n  0 3 4  (1e-30) (1e-30) 0  uvs 0 0  1 0.5  -2 3 m\n"
             "triangle 0 0 0  1 0 0  0 1 0  uvs 0.25 0.75  1 0  0 1  normals 0 0 1  0 0 1  0 0 -1 m  # either order\n"
             "triangle 0 0 0  1 0 0  0 1 0  uvs 0 0 1 0 0 1 m\n"
             "triangle 0 0 0  1 0 0  0 1 0  normals 1 0 0 0 1 0 0 0 1 m\n"
             "triangle 0 0 0  1 0 0  0 1 0 m\n"
             "quad 0 0 0  1 0 0  0 1 0 m\n", NULL, &s);
    assert_int_equal(s.shape_count, 7);
    /* In a block the material may be left out after the clauses, as after the corners. */
    const scene_shape *t = &s.shapes[0];
    assert_true(t->has_normals);
    assert_false(t->has_uvs);
    assert_int_equal(t->material, -1);
    assert_int_equal(s.instances[0].material, 0);

    t = &s.shapes[1];
    assert_int_equal(t->type, SHAPE_TRIANGLE);
    assert_int_equal(t->material, 0);
    assert_vector_equal(t->points[2], 0, 1, 0);
    assert_true(t->has_normals);
    assert_true(t->has_uvs);
    /* Stored at unit length, also a tiny one. */
    assert_vector_equal(t->normals[0], 0, 0, 1);
    assert_vector_equal(t->normals[1], 0, 0.6, 0.8);
    assert_vector_equal(t->normals[2], sqrt(0.5), sqrt(0.5), 0);
    assert_double_equal(t->uvs[0][0], 0, 0);
    assert_double_equal(t->uvs[0][1], 0, 0);
    assert_double_equal(t->uvs[1][0], 1, 0);
    assert_double_equal(t->uvs[1][1], 0.5, 0);
    assert_double_equal(t->uvs[2][0], -2, 0);   /* any finite value */
    assert_double_equal(t->uvs[2][1], 3, 0);

    t = &s.shapes[2];
    assert_true(t->has_normals && t->has_uvs);
    assert_double_equal(t->uvs[0][0], 0.25, 0);
    assert_double_equal(t->uvs[0][1], 0.75, 0);
    assert_vector_equal(t->normals[2], 0, 0, -1);  /* need not agree with the corner order */
    assert_int_equal(t->material, 0);

    t = &s.shapes[3];
    assert_false(t->has_normals);
    assert_true(t->has_uvs);
    for (int k = 0; k < 3; k++)
        assert_vector_equal(t->normals[k], 0, 0, 0);
    assert_double_equal(t->uvs[2][1], 1, 0);

    t = &s.shapes[4];
    assert_true(t->has_normals);
    assert_false(t->has_uvs);
    assert_vector_equal(t->normals[1], 0, 1, 0);
    for (int k = 0; k < 3; k++) {
        assert_double_equal(t->uvs[k][0], 0, 0);
        assert_double_equal(t->uvs[k][1], 0, 0);
    }

    /* Without the clauses, and for every other shape: flat, no uvs, all zero. */
    for (int i = 5; i <= 6; i++) {
        t = &s.shapes[i];
        assert_false(t->has_normals);
        assert_false(t->has_uvs);
        for (int k = 0; k < 3; k++) {
            assert_vector_equal(t->normals[k], 0, 0, 0);
            assert_double_equal(t->uvs[k][0], 0, 0);
            assert_double_equal(t->uvs[k][1], 0, 0);
        }
    }
    assert_int_equal(s.shapes[6].type, SHAPE_QUAD);
    scene_free(&s);

    /* A material called normals or uvs still works as the last word, as it always did. */
    parse_ok("material normals lambertian 1 1 1\n"
             "material uvs lambertian 1 0 0\n"
             "triangle 0 0 0  1 0 0  0 1 0 normals\n"
             "triangle 0 0 0  1 0 0  0 1 0 uvs\n"
             "triangle 0 0 0  1 0 0  0 1 0 normals 0 0 1 0 0 1 0 0 1 uvs\n"
             "triangle 0 0 0  1 0 0  0 1 0 uvs 0 0 1 0 0 1 normals  # a comment\n", NULL, &s);
    assert_int_equal(s.shape_count, 4);
    assert_int_equal(s.shapes[0].material, 0);
    assert_false(s.shapes[0].has_normals);
    assert_int_equal(s.shapes[1].material, 1);
    assert_false(s.shapes[1].has_uvs);
    assert_true(s.shapes[2].has_normals);
    assert_int_equal(s.shapes[2].material, 1);
    assert_true(s.shapes[3].has_uvs);
    assert_int_equal(s.shapes[3].material, 0);
    scene_free(&s);
}

/* The example of docs/scene-format.md, "Triangle normals and uvs", exactly. */
static void test_documented_triangle_example(void **state)
{
    (void)state;
    scene s;
    parse_ok("texture photo image \"photo.png\"\n"
             "material print lambertian @photo\n"
             "triangle -1 0 0   1 0 0   1 1 0   normals -0.5 0 1  0.5 0 1  0.5 0 1   uvs 0 0  1 0  1 1   print\n"
             "triangle -1 0 0   1 1 0  -1 1 0   normals -0.5 0 1  0.5 0 1 -0.5 0 1   uvs 0 0  1 1  0 1   print\n",
             NULL, &s);
    assert_int_equal(s.shape_count, 2);
    double c = 1 / sqrt(1.25);
    for (int i = 0; i < 2; i++) {
        assert_true(s.shapes[i].has_normals);
        assert_true(s.shapes[i].has_uvs);
        assert_int_equal(s.shapes[i].material, 0);
        assert_vector_equal(s.shapes[i].normals[0], -0.5 * c, 0, c);
    }
    assert_vector_equal(s.shapes[1].normals[2], -0.5 * c, 0, c);
    assert_double_equal(s.shapes[1].uvs[2][0], 0, 0);
    assert_double_equal(s.shapes[1].uvs[2][1], 1, 0);
    scene_free(&s);
}

static void test_triangle_normal_and_uv_errors(void **state)
{
    (void)state;
    const char *m = "material m lambertian 1 1 1\n";
    char text[512];
#define TRIANGLE_ERROR(rest, prefix, phrase)                                  \
    do {                                                                      \
        snprintf(text, sizeof text, "%striangle 0 0 0 1 0 0 0 1 0 %s", m, rest); \
        assert_parse_error(text, prefix, phrase);                             \
    } while (0)
    /* "triangle 0 0 0 1 0 0 0 1 0 " is 27 bytes: the clause word is at column 28, its
     * first number at 36 (normals) or 32 (uvs); a missing number is reported just after
     * the last token. */
    TRIANGLE_ERROR("normals 0 0 0  0 0 1  0 0 1 m", "s.txt:2:36: ",
                   "the triangle's first normal is zero (0 0 0), so it has no direction");
    TRIANGLE_ERROR("normals 0 0 1  0 0 1  -0 0 0 m", "s.txt:2:50: ", "the triangle's third normal is zero");
    TRIANGLE_ERROR("normals 0 0 1  nan 0 1  0 0 1 m", "s.txt:2:43: ",
                   "expected a number for the triangle's second normal x, found 'nan' (NaN and infinity are not "
                   "allowed)");
    TRIANGLE_ERROR("normals 0 0 1  0 0 1  0 0 -inf m", "s.txt:2:54: ",
                   "expected a number for the triangle's third normal z, found '-inf' (NaN and infinity");
    TRIANGLE_ERROR("normals 0 0 1e999  0 0 1  0 0 1 m", "s.txt:2:40: ",
                   "expected a finite number for the triangle's first normal z, found '1e999' (out of range)");
    TRIANGLE_ERROR("normals 0 0 1e39  0 0 1  0 0 1 m", "s.txt:2:40: ",
                   "the triangle's first normal z is 1e+39, too large for the renderer's 32-bit floats");
    TRIANGLE_ERROR("normals 0 (0/0) 1  0 0 1  0 0 1 m", "s.txt:2:40: ", "division by zero");
    TRIANGLE_ERROR("normals (10^400) 0 1  0 0 1  0 0 1 m", "s.txt:2:39: ", "the result of '^' is infinite (too large)");
    TRIANGLE_ERROR("normals 0 0 1  0 0 1 m", "s.txt:2:49: ",
                   "expected a number for the triangle's third normal x, found 'm'");
    TRIANGLE_ERROR("normals 0 0 1  0 0 1  0 0", "s.txt:2:53: ",
                   "expected a number for the triangle's third normal z, found end of line");
    TRIANGLE_ERROR("normals", "s.txt:2:35: ", "expected a number for the triangle's first normal x, found end of line");
    TRIANGLE_ERROR("uvs 0 nan  1 0  0 1 m", "s.txt:2:34: ",
                   "expected a number for the triangle's first uv v, found 'nan' (NaN and infinity are not allowed)");
    TRIANGLE_ERROR("uvs 0 0  1 0  infinity 1 m", "s.txt:2:42: ",
                   "expected a number for the triangle's third uv u, found 'infinity'");
    TRIANGLE_ERROR("uvs 0 0  1e39 0  0 1 m", "s.txt:2:37: ",
                   "the triangle's second uv u is 1e+39, too large for the renderer's 32-bit floats");
    TRIANGLE_ERROR("uvs 0 0  1 0  0 (1/0) m", "s.txt:2:46: ", "division by zero");
    TRIANGLE_ERROR("uvs 0 0  1 0  0", "s.txt:2:43: ", "expected a number for the triangle's third uv v, found end of line");
    TRIANGLE_ERROR("normals 0 0 1 0 0 1 0 0 1 normals 0 0 1 0 0 1 0 0 1 m", "s.txt:2:54: ",
                   "triangle clause 'normals' given twice in one statement (first at column 28)");
    TRIANGLE_ERROR("uvs 0 0 1 0 0 1 normals 0 0 1 0 0 1 0 0 1 uvs 0 0 1 0 0 1 m", "s.txt:2:70: ",
                   "triangle clause 'uvs' given twice in one statement (first at column 28)");
    TRIANGLE_ERROR("normal 0 0 1 0 0 1 0 0 1 m", "s.txt:2:28: ",
                   "unknown triangle clause 'normal' (expected normals or uvs, or a material defined earlier as the "
                   "last word)");
    TRIANGLE_ERROR("m normals 0 0 1 0 0 1 0 0 1", "s.txt:2:30: ",
                   "unexpected 'normals' after the triangle (expected end of line)");
    TRIANGLE_ERROR("uvs 0 0 1 0 0 1 nope", "s.txt:2:44: ", "the triangle's material 'nope' is not defined");
    /* At the top level the material is still needed after the clauses. */
    TRIANGLE_ERROR("uvs 0 0 1 0 0 1", "s.txt:2:43: ",
                   "expected a material name for the triangle, found end of line (a shape needs a material outside "
                   "a group)");
#undef TRIANGLE_ERROR
}

/* ------------------------------------------------------------------ groups and transforms */

static void test_transform_order(void **state)
{
    (void)state;
    scene s;
    /* The first transform written applies first: rotate, then move. */
    parse_ok("material m lambertian 1 1 1\n"
             "group material m {\n"
             "    rotate 0 0 1 90\n"
             "    translate 10 0 0\n"
             "    triangle 0 0 0  1 0 0  0 1 0\n"
             "}\n"
             "group material m {\n"
             "    translate 10 0 0\n"
             "    rotate 0 0 1 90\n"
             "    triangle 0 0 0  1 0 0  0 1 0\n"
             "}\n", NULL, &s);
    assert_int_equal(s.instance_count, 2);
    assert_maps(&s.instances[0], 1, 0, 0, 10, 1, 0);
    assert_maps(&s.instances[1], 1, 0, 0, 0, 11, 0);
    scene_free(&s);

    /* The example of the format description: rotate 15 degrees about y, then move. */
    parse_ok("material m lambertian 1 1 1\n"
             "group {\n"
             "    rotate 0 1 0 15\n"
             "    translate 265 0 295\n"
             "    box 0 0 0  165 330 165 m\n"
             "}\n", NULL, &s);
    double c = cos(15 * 3.14159265358979323846 / 180), sn = sin(15 * 3.14159265358979323846 / 180);
    /* Right-handed about +y: +x turns towards -z, +z towards +x. */
    assert_maps(&s.instances[0], 1, 0, 0, 265 + c, 0, 295 - sn);
    assert_maps(&s.instances[0], 0, 0, 1, 265 + sn, 0, 295 + c);
    assert_maps(&s.instances[0], 0, 1, 0, 265, 1, 295);
    scene_free(&s);

    /* An enclosing block's transform applies after the inner one's. */
    parse_ok("material m lambertian 1 1 1\n"
             "group {\n"
             "    translate 0 0 5\n"
             "    group {\n"
             "        scale 2\n"
             "        rotate 1 0 0 90\n"
             "        quad 0 0 0  1 0 0  0 1 0 m\n"
             "    }\n"
             "}\n", NULL, &s);
    assert_int_equal(s.instance_count, 1);
    assert_maps(&s.instances[0], 0, 1, 0, 0, 0, 7);       /* (0,1,0) -> (0,2,0) -> (0,0,2) -> (0,0,7) */
    assert_maps(&s.instances[0], 1, 0, 0, 2, 0, 5);
    scene_free(&s);
}

static void test_scale_matrix_and_rotate_forms(void **state)
{
    (void)state;
    scene s;
    parse_ok("material m lambertian 1 1 1\n"
             "group material m {\n  scale 1 2 -3   # a negative factor mirrors\n  sphere 0 0 0 1\n}\n"
             "group material m {\n  matrix 0 -1 0 1  1 0 0 2  0 0 2 3\n  sphere 0 0 0 1\n}\n"
             "group material m {\n  rotate 0 0 7 90   # the axis need not be a unit vector\n  sphere 0 0 0 1\n}\n"
             "group material m {\n  scale 3\n  translate 1 1 1\n  scale 0.5\n  sphere 0 0 0 1\n}\n", NULL, &s);
    assert_int_equal(s.instance_count, 4);
    assert_maps(&s.instances[0], 1, 1, 1, 1, 2, -3);
    assert_maps(&s.instances[1], 0, 0, 0, 1, 2, 3);
    assert_maps(&s.instances[1], 1, 0, 0, 1, 3, 3);       /* column 0 of the matrix, plus column 3 */
    assert_maps(&s.instances[1], 0, 1, 0, 0, 2, 3);
    assert_maps(&s.instances[1], 0, 0, 1, 1, 2, 5);
    assert_maps(&s.instances[2], 1, 0, 0, 0, 1, 0);
    assert_maps(&s.instances[3], 2, 0, 0, 3.5, 0.5, 0.5); /* (2,0,0) -> (6,0,0) -> (7,1,1) -> (3.5,.5,.5) */
    /* The shape keeps its own coordinates; the instance carries the transform. */
    assert_vector_equal(s.shapes[0].points[0], 0, 0, 0);
    scene_free(&s);
}

static void test_transform_errors(void **state)
{
    (void)state;
    assert_parse_error("group {\n  rotate 0 0 0 45\n}", "s.txt:2:10: ",
                       "the rotation axis (0 0 0) has zero length");
    assert_parse_error("group {\n  scale 0\n}", "s.txt:2:9: ",
                       "the scale must not be 0 on any axis (it would flatten the contents), found 0");
    assert_parse_error("group {\n  scale 1 0 2\n}", "s.txt:2:11: ", "the scale must not be 0 on any axis");
    assert_parse_error("group {\n  scale 1 2 0\n}", "s.txt:2:13: ", "the scale must not be 0 on any axis");
    assert_parse_error("group {\n  scale 1 2\n}", "s.txt:2:12: ", "expected a number for the scale z, found end of line");
    assert_parse_error("group {\n  scale 1e-50\n}", "s.txt:2:9: ", "too small for the renderer's 32-bit floats");
    assert_parse_error("group {\n  matrix 1 0 0 0  0 1 0 0  2 0 0 0\n}", "s.txt:2:3: ",
                       "the matrix is singular (the determinant of its 3x3 part is 0); a transform must be invertible");
    assert_parse_error("group {\n  matrix 1e-5 0 0 0  0 1e-5 0 0  0 0 1e-5 0\n}", "s.txt:2:3: ", "the matrix is singular");
    assert_parse_error("group {\n  matrix 1 0 0 0  0 1 0 0  0 0 1\n}", "s.txt:2:33: ",
                       "expected a number for the matrix element M23, found end of line");
    assert_parse_error("group {\n  translate 1 2 3 4\n}", "s.txt:2:19: ", "unexpected '4' after the translation");
    assert_parse_error("group {\n  translate 1e39 0 0\n}", "s.txt:2:13: ", "too large for the renderer's 32-bit floats");
    assert_parse_error("group {\n  rotate 0 1 0\n}", "s.txt:2:15: ",
                       "expected a number for the rotation angle in degrees, found end of line");

    /* Transforms come first in their block, and only inside one. */
    assert_parse_error("material m lambertian 1 1 1\ngroup material m {\n  sphere 0 0 0 1\n  translate 1 0 0\n}",
                       "s.txt:4:3: ", "'translate' after the group's contents: transforms come first in a group");
    assert_parse_error("volume 1 1 1 1 {\n  group {\n  }\n  scale 2\n}", "s.txt:4:3: ",
                       "'scale' after the volume's contents: transforms come first in a group");
    assert_parse_error("group {\n  material m lambertian 1 1 1\n  rotate 0 1 0 5\n}", "s.txt:3:3: ",
                       "transforms come first in a group");
    assert_parse_error("translate 1 2 3", "s.txt:1:1: ",
                       "'translate' outside a block: a transform applies to the contents of a group, instance or volume");
    assert_parse_error("group {\n}\nmatrix 1 0 0 0 0 1 0 0 0 0 1 0", "s.txt:3:1: ", "'matrix' outside a block");
    /* A composition past the float range is caught where it is placed. */
    assert_parse_error("material m lambertian 1 1 1\ngroup {\n scale 1e30\n group {\n  scale 1e30\n  sphere 0 0 0 1 m\n"
                       " }\n}", "s.txt:6:3: ", "too large for the renderer's 32-bit floats");
}

static void test_named_group_placed_again_shares_objects(void **state)
{
    (void)state;
    scene s;
    parse_ok("material m lambertian 1 1 1\n"
             "group pair material m {\n"
             "    translate 0 1 0\n"
             "    sphere 0 0 0 1\n"
             "    group {\n"
             "        translate 3 0 0\n"
             "        quad 0 0 0  1 0 0  0 0 1\n"
             "    }\n"
             "}\n"
             "instance pair {\n"
             "    translate 100 0 0   # after the group's own transform\n"
             "}\n"
             "instance pair\n", NULL, &s);
    /* Two objects (the group's sphere, the inner group's quad), each placed three times. */
    assert_int_equal(s.object_count, 2);
    assert_int_equal(s.shape_count, 2);
    assert_int_equal(s.instance_count, 6);
    for (int i = 0; i < 6; i++) {
        assert_int_equal(s.instances[i].object, i % 2);
        assert_int_equal(s.instances[i].material, 0);
    }
    assert_maps(&s.instances[0], 0, 0, 0, 0, 1, 0);
    assert_maps(&s.instances[1], 0, 0, 0, 3, 1, 0);
    assert_maps(&s.instances[2], 0, 0, 0, 100, 1, 0);
    assert_maps(&s.instances[3], 0, 0, 0, 103, 1, 0);
    assert_maps(&s.instances[4], 0, 0, 0, 0, 1, 0);
    assert_maps(&s.instances[5], 0, 0, 0, 3, 1, 0);
    scene_free(&s);

    /* A group's placements are relative to its parent's frame: instancing a nested
     * group elsewhere does not repeat the transforms of the blocks around it. */
    parse_ok("material m lambertian 1 1 1\n"
             "group {\n"
             "    translate 50 0 0\n"
             "    group inner {\n"
             "        translate 1 0 0\n"
             "        sphere 0 0 0 1 m\n"
             "    }\n"
             "}\n"
             "group outer {\n"
             "    translate 0 0 7\n"
             "    instance inner { \n"
             "        scale 2\n"
             "    }\n"
             "}\n"
             "instance outer {\n"
             "    translate 0 9 0\n"
             "}\n", NULL, &s);
    assert_int_equal(s.object_count, 1);
    assert_int_equal(s.instance_count, 3);
    assert_maps(&s.instances[0], 0, 0, 0, 51, 0, 0);
    assert_maps(&s.instances[1], 0, 0, 0, 2, 0, 7);        /* inner's (1,0,0), scaled, then moved */
    assert_maps(&s.instances[2], 0, 0, 0, 2, 9, 7);
    assert_maps(&s.instances[2], 1, 0, 0, 4, 9, 7);
    scene_free(&s);
}

static void test_material_inheritance(void **state)
{
    (void)state;
    scene s;
    parse_ok("material red lambertian 1 0 0\n"
             "material blue lambertian 0 0 1\n"
             "material green lambertian 0 1 0\n"
             "group material red {\n"
             "    sphere 0 0 0 1              # red, from the group\n"
             "    sphere 2 0 0 1 blue         # keeps its own\n"
             "    group {\n"
             "        sphere 4 0 0 1          # red, from the nearest group with a material\n"
             "    }\n"
             "    group material green {\n"
             "        sphere 6 0 0 1          # green\n"
             "    }\n"
             "}\n", NULL, &s);
    assert_int_equal(s.instance_count, 3);
    /* Instances come in the order of each block's first shape. */
    assert_int_equal(s.instances[0].material, 0);
    assert_int_equal(s.objects[s.instances[0].object].shape_count, 2);
    int first = s.objects[s.instances[0].object].first_shape;
    assert_int_equal(s.shapes[first].material, -1);
    assert_int_equal(s.shapes[first + 1].material, 1);
    assert_int_equal(s.instances[1].material, 0);
    assert_int_equal(s.instances[2].material, 2);
    scene_free(&s);

    /* An instance's material fills only what has no material yet. */
    parse_ok("material red lambertian 1 0 0\n"
             "material blue lambertian 0 0 1\n"
             "material green lambertian 0 1 0\n"
             "group material red {\n"
             "    group plain {\n"
             "        sphere 0 0 0 1\n"
             "    }\n"
             "    group coloured material blue {\n"
             "        sphere 0 0 0 1\n"
             "    }\n"
             "}\n"
             "instance plain material green\n"
             "instance coloured material green\n"
             "group material blue {\n"
             "    instance plain\n"
             "}\n", NULL, &s);
    assert_int_equal(s.instance_count, 5);
    assert_int_equal(s.instances[0].material, 0);          /* plain, where defined: red */
    assert_int_equal(s.instances[1].material, 1);          /* coloured: its own blue */
    assert_int_equal(s.instances[2].material, 2);          /* plain again, green */
    assert_int_equal(s.instances[3].material, 1);          /* coloured stays blue */
    assert_int_equal(s.instances[4].material, 1);          /* plain inside a blue group */
    scene_free(&s);

    assert_parse_error("group material nope {\n}", "s.txt:1:16: ",
                       "the group's material 'nope' is not defined (a material must be defined before the groups "
                       "that use it)");
    assert_parse_error("group material {\n}", "s.txt:1:16: ", "expected a material name for the group, found '{'");
    assert_parse_error("group g {\n}\ninstance g material nope", "s.txt:3:21: ", "the instance's material 'nope' is not defined");
}

static void test_shapes_without_any_material(void **state)
{
    (void)state;
    /* A shape in a group needs a material from somewhere when it is placed. */
    assert_parse_error("group {\n  translate 1 0 0\n  quad 0 0 0 1 0 0 0 1 0\n}", "s.txt:3:3: ",
                       "this shape has no material: give it one, or give a group around it (or the instance that "
                       "places it) a material");
    assert_parse_error("material m lambertian 1 1 1\ngroup g {\n  sphere 0 0 0 1 m\n  box 0 0 0 1 1 1\n}\n"
                       "instance g material m", "s.txt:4:3: ", "this shape has no material");
    /* A volume's boundary and a mesh (which may carry its own) need none. */
    scene s;
    parse_ok("volume 0.5 1 1 1 {\n  sphere 0 0 0 1\n}\ngroup {\n  mesh \"a.obj\"\n}\n", NULL, &s);
    assert_int_equal(s.instance_count, 2);
    assert_int_equal(s.instances[0].material, -1);
    assert_int_equal(s.instances[1].material, -1);
    scene_free(&s);
}

static void test_meshes(void **state)
{
    write_text(state, "models/a.obj", "# not read by the parser\n");
    write_text(state, "models/part.txt", "mesh \"a.obj\"            # next to part.txt\nmesh \"../models/a.obj\"\n");
    const char *directory = ((scratch *)*state)->directory;
    write_text(state, "top.txt",
               "material m lambertian 1 1 1\n"
               "material n metal 1 1 1\n"
               "mesh \"models/a.obj\" m\n"
               "group material n {\n"
               "    translate 0 2 0\n"
               "    mesh \"models/a.obj\"\n"
               "    mesh \"models/b.obj\" m\n"
               "    include \"models/part.txt\"\n"
               "}\n");
    scene s;
    load_file_ok(state, "top.txt", NULL, &s);
    char expected[512];
    /* One mesh (and one object) per resolved path; "models/../models/a.obj" is spelt
     * differently, so it is a mesh of its own (the loader may read it twice). */
    assert_int_equal(s.mesh_count, 3);
    snprintf(expected, sizeof expected, "%s/models/a.obj", directory);
    assert_string_equal(s.meshes[0].path, expected);
    snprintf(expected, sizeof expected, "%s/top.txt:3:6", directory);
    assert_string_equal(s.meshes[0].position, expected);
    assert_int_equal(s.meshes[0].default_material, -1);
    assert_null(s.meshes[0].positions);
    assert_int_equal(s.meshes[0].triangle_count, 0);
    snprintf(expected, sizeof expected, "%s/models/b.obj", directory);
    assert_string_equal(s.meshes[1].path, expected);
    snprintf(expected, sizeof expected, "%s/models/../models/a.obj", directory);
    assert_string_equal(s.meshes[2].path, expected);
    snprintf(expected, sizeof expected, "%s/models/part.txt:2:6", directory);
    assert_string_equal(s.meshes[2].position, expected);

    assert_int_equal(s.object_count, 3);
    for (int i = 0; i < 3; i++) {
        assert_int_equal(s.objects[i].mesh, i);
        assert_int_equal(s.objects[i].shape_count, 0);
    }
    assert_int_equal(s.instance_count, 5);
    int objects[5] = {0, 0, 1, 0, 2}, materials[5] = {0, 1, 0, 1, 1};
    for (int i = 0; i < 5; i++) {
        assert_int_equal(s.instances[i].object, objects[i]);
        assert_int_equal(s.instances[i].material, materials[i]);
    }
    assert_true(is_identity(&s.instances[0]));
    assert_maps(&s.instances[1], 0, 0, 0, 0, 2, 0);
    assert_maps(&s.instances[3], 0, 0, 0, 0, 2, 0);
    scene_free(&s);

    assert_parse_error("mesh \"\" m", "s.txt:1:6: ", "expected a path inside the quotes of the mesh, found an empty string");
    assert_parse_error("mesh a.obj", "s.txt:1:6: ", "expected a quoted path for the mesh (e.g. \"file.png\"), found 'a.obj'");
    char long_path[1100];
    memset(long_path, 'x', 1024);
    long_path[1024] = '\0';
    char text[1200];
    snprintf(text, sizeof text, "group {\n  mesh \"%s\"\n}", long_path);
    assert_parse_error(text, "s.txt:2:8: ", "the path of the mesh is 1024 bytes long once resolved; the limit is 1023");
}

static void test_volumes(void **state)
{
    (void)state;
    scene s;
    parse_ok("material glass dielectric 1.5\n"
             "volume 0.2 0.1 0.5 1 {\n"
             "    translate 0 1 0\n"
             "    box 0 0 0 1 1 1\n"
             "    group material glass {\n"
             "        sphere 0 0 0 1\n"
             "    }\n"
             "    volume 3 1 1 1 {\n"
             "        sphere 5 0 0 1\n"
             "    }\n"
             "}\n"
             "group material glass {\n"
             "    sphere 0 0 0 1             # not in a volume\n"
             "}\n", NULL, &s);
    assert_int_equal(s.instance_count, 4);
    assert_true(s.instances[0].volume);
    assert_double_equal(s.instances[0].density, 0.2, 1e-7);
    assert_vector_equal(s.instances[0].volume_albedo, 0.1, 0.5, 1);
    assert_int_equal(s.instances[0].material, -1);
    assert_int_equal(s.objects[s.instances[0].object].shape_count, 6);
    assert_maps(&s.instances[0], 0, 0, 0, 0, 1, 0);
    /* A group inside a volume is part of the volume's boundary. */
    assert_true(s.instances[1].volume);
    assert_double_equal(s.instances[1].density, 0.2, 1e-7);
    assert_int_equal(s.instances[1].material, 0);
    assert_maps(&s.instances[1], 0, 0, 0, 0, 1, 0);
    /* The nearest volume counts. */
    assert_true(s.instances[2].volume);
    assert_double_equal(s.instances[2].density, 3, 0);
    assert_vector_equal(s.instances[2].volume_albedo, 1, 1, 1);
    assert_false(s.instances[3].volume);
    assert_double_equal(s.instances[3].density, 0, 0);
    scene_free(&s);

    /* A named group's placements keep the volumes inside it... */
    parse_ok("group fog {\n  volume 1 0.5 0.5 0.5 {\n    sphere 0 0 0 1\n  }\n}\ninstance fog\n", NULL, &s);
    assert_int_equal(s.instance_count, 2);
    assert_true(s.instances[1].volume);
    assert_double_equal(s.instances[1].volume_albedo[0], 0.5, 0);
    scene_free(&s);
    /* ... but not one around it: placed elsewhere, this sphere is a surface without a material. */
    assert_parse_error("volume 1 0.5 0.5 0.5 {\n  group fog {\n    sphere 0 0 0 1\n  }\n}\ninstance fog\n",
                       "s.txt:3:5: ", "this shape has no material");

    assert_parse_error("volume 0 1 1 1 {\n}", "s.txt:1:8: ", "the volume's density must be > 0, found 0");
    assert_parse_error("volume -2 1 1 1 {\n}", "s.txt:1:8: ", "the volume's density must be > 0, found -2");
    assert_parse_error("volume 1 1 1.5 1 {\n}", "s.txt:1:12: ",
                       "the green component of the volume's albedo must be between 0 and 1, found 1.5");
    assert_parse_error("volume 1 -0.1 1 1 {\n}", "s.txt:1:10: ", "the red component of the volume's albedo");
    assert_parse_error("volume 1 1 1 1\n", "s.txt:1:15: ", "expected '{' at the end of the volume line, found end of line");
    assert_parse_error("volume 1 1 1", "s.txt:1:13: ",
                       "expected a number for the blue component of the volume's albedo, found end of line");
}

/* A volume's boundary must be closed: 1 to 3 flat shapes in one boundary object cannot
 * be (a single quad is the usual mistake); 0 or 4 and more are not judged. */
static void test_volume_boundary_must_be_closed(void **state)
{
    (void)state;
    assert_parse_error("volume 1 1 1 1 {\n  quad 0 0 0  1 0 0  0 1 0\n}\n", "s.txt:2:3: ",
                       "this quad is the only flat surface of a volume's boundary, which must be closed: one quad "
                       "encloses nothing (use a box, a sphere or a closed mesh, or put the quad outside the volume)");
    assert_parse_error("volume 1 1 1 1 {\n  translate 0 1 0\n  triangle 0 0 0  1 0 0  0 1 0\n}\n", "s.txt:3:3: ",
                       "this triangle is the only flat surface of a volume's boundary");
    assert_parse_error("volume 1 1 1 1 {\n  sphere 0 0 0 1\n  triangle 0 0 0  1 0 0  0 1 0\n"
                       "  quad 0 0 0  1 0 0  0 1 0\n  triangle 0 0 0  1 0 0  0 0 1\n}\n", "s.txt:3:3: ",
                       "this triangle is one of only 3 flat surfaces (triangles and quads) of a volume's boundary, "
                       "which must be closed: fewer than 4 flat faces enclose nothing");
    /* A group inside a volume is a boundary of its own (with a material: a pane in fog). */
    assert_parse_error("material glass dielectric 1.5\nvolume 1 1 1 1 {\n  sphere 0 0 0 1\n"
                       "  group material glass {\n    quad 0 0 0  1 0 0  0 1 0\n  }\n}\n", "s.txt:5:5: ",
                       "this quad is the only flat surface of a volume's boundary");
    /* Placed by an instance, the group's volume is the same object, reported once. */
    assert_parse_error("group g {\n  volume 1 1 1 1 {\n    quad 0 0 0  1 0 0  0 1 0\n  }\n}\ninstance g {\n"
                       "  translate 5 0 0\n}\n", "s.txt:3:5: ", "this quad is the only flat surface");

    scene s;
    /* A box (six quads), a tetrahedron's four triangles, spheres alone: accepted. */
    parse_ok("volume 1 1 1 1 {\n  box 0 0 0 1 1 1\n}\n"
             "volume 1 1 1 1 {\n"
             "  triangle 0 0 0  0 1 0  1 0 0\n  triangle 0 0 0  1 0 0  0 0 1\n"
             "  triangle 0 0 0  0 0 1  0 1 0\n  triangle 1 0 0  0 1 0  0 0 1\n}\n"
             "volume 1 1 1 1 {\n  sphere 0 0 0 1\n  moving_sphere 0 0 0  1 0 0  1\n}\n", NULL, &s);
    assert_int_equal(s.instance_count, 3);
    assert_true(s.instances[0].volume && s.instances[1].volume && s.instances[2].volume);
    scene_free(&s);
    /* A single quad outside any volume is a surface as always. */
    parse_ok("material m lambertian 1 1 1\nquad 0 0 0  1 0 0  0 1 0 m\nvolume 1 1 1 1 {\n  sphere 0 0 0 1\n}\n",
             NULL, &s);
    assert_int_equal(s.instance_count, 2);
    scene_free(&s);
}

static void test_instance_forms_and_errors(void **state)
{
    (void)state;
    scene s;
    parse_ok("material m lambertian 1 1 1\n"
             "group g material m {\n  sphere 0 0 0 1\n}\n"
             "instance g {   # a comment after the brace\n"
             "    rotate 0 1 0 90\n"
             "    translate 1 0 0\n"
             "} # and after the closing one\n"
             "instance g {\n}\n"
             "instance g material m\n", NULL, &s);
    assert_int_equal(s.instance_count, 4);
    assert_maps(&s.instances[1], 0, 0, 1, 2, 0, 0);
    assert_true(is_identity(&s.instances[2]));
    assert_true(is_identity(&s.instances[3]));
    scene_free(&s);

    /* An empty group places nothing, and so does its instance. */
    parse_ok("group empty {\n}\ninstance empty\n", NULL, &s);
    assert_int_equal(s.instance_count, 0);
    assert_int_equal(s.object_count, 0);
    scene_free(&s);

    assert_parse_error("instance nothing", "s.txt:1:10: ",
                       "unknown group 'nothing' (a group must be defined with group nothing { ... } before it is "
                       "instanced)");
    assert_parse_error("group self {\n  instance self\n}", "s.txt:2:12: ",
                       "group 'self' is still open: a group cannot contain an instance of itself");
    assert_parse_error("group outer {\n  group inner {\n    instance outer {\n    }\n  }\n}", "s.txt:3:14: ",
                       "group 'outer' is still open");
    assert_parse_error("group g {\n}\n\ngroup g {\n}", "s.txt:4:7: ", "group 'g' is already defined at s.txt:1:7");
    assert_parse_error("group g {\n}\ngroup {\n  group g {\n  }\n}", "s.txt:4:9: ", "group 'g' is already defined");
    assert_parse_error("group g {\n}\ninstance g {\n  sphere 0 0 0 1\n}", "s.txt:4:3: ",
                       "only transforms (translate, rotate, scale, matrix) may appear inside an instance block, found "
                       "'sphere'");
    assert_parse_error("group g {\n}\ninstance g {\n  set x 1\n}", "s.txt:4:3: ", "inside an instance block");
    assert_parse_error("instance", "s.txt:1:9: ", "expected a group name after instance, found end of line");
    assert_parse_error("group g {\n}\ninstance g extra", "s.txt:3:12: ",
                       "expected '{' at the end of the instance line (or end of line), found 'extra'");
    assert_parse_error("group $g {\n}", "s.txt:1:7: ", "expected a group name (letters, digits, '_', '-' and '.'), found '$g'");
    assert_parse_error("group g h {\n}", "s.txt:1:9: ", "expected '{' at the end of the group line, found 'h'");
    assert_parse_error("group g", "s.txt:1:8: ", "expected '{' at the end of the group line, found end of line");
}

static void test_braces(void **state)
{
    (void)state;
    scene s;
    /* Blocks with nothing in them, comments and blank lines, '{' right after the keyword. */
    parse_ok("group{\n\n  # nothing\n}\nvolume 1 1 1 1{\n}\n", NULL, &s);
    assert_int_equal(s.instance_count, 0);
    scene_free(&s);

    assert_parse_error("render spp 1\n  group g {\n  group {\n  }\n", "s.txt:2:3: ",
                       "this group is never closed (expected a '}' on a line of its own before the end of s.txt)");
    assert_parse_error("volume 1 1 1 1 {\n", "s.txt:1:1: ", "this volume is never closed");
    assert_parse_error("group g {\n}\ninstance g {\n  translate 1 0 0", "s.txt:3:1: ", "this instance block is never closed");
    assert_parse_error("group {\n}\n}", "s.txt:3:1: ", "unexpected '}' (no block is open)");
    assert_parse_error("material m lambertian 1 1 1\ngroup {\n  sphere 0 0 0 1 m }\n}", "s.txt:3:20: ",
                       "unexpected '}' (a '}' closes a block on a line of its own)");
    assert_parse_error("group {\n} group {", "s.txt:2:3: ",
                       "unexpected 'group' after '}' (a '}' stands alone on its line) (expected end of line)");
    assert_parse_error("group {\n}}", "s.txt:2:2: ", "unexpected '}' (a '}' closes a block on a line of its own)");
    assert_parse_error("group { sphere 0 0 0 1\n}", "s.txt:1:9: ", "unexpected 'sphere' after '{' (a block's '{' ends its line)");
    assert_parse_error("{\n}", "s.txt:1:1: ", "unexpected '{' (only a group, instance or volume line ends with '{')");
    assert_parse_error("camera fov 30 {", "s.txt:1:15: ", "unexpected '{'");
}

/* Builds depth nested groups, each with a translate, the innermost with a sphere. */
static char *nested_groups(int depth)
{
    size_t size = (size_t)depth * 40 + 128;
    char *text = malloc(size);
    assert_non_null(text);
    size_t used = (size_t)snprintf(text, size, "material m lambertian 1 1 1\n");
    for (int i = 0; i < depth; i++)
        used += (size_t)snprintf(text + used, size - used, "group {\ntranslate 1 0 0\n");
    used += (size_t)snprintf(text + used, size - used, "sphere 0 0 0 1 m\n");
    for (int i = 0; i < depth; i++)
        used += (size_t)snprintf(text + used, size - used, "}\n");
    return text;
}

static void test_nesting_limit(void **state)
{
    (void)state;
    char *text = nested_groups(64);
    scene s;
    parse_ok(text, NULL, &s);
    assert_int_equal(s.instance_count, 1);
    assert_maps(&s.instances[0], 0, 0, 0, 64, 0, 0);
    scene_free(&s);
    free(text);

    text = nested_groups(65);
    /* Line 2 + 2 * 64 opens the 65th group. */
    assert_parse_error(text, "s.txt:130:1: ", "blocks nested too deeply: this group would be level 65, the limit is 64");
    free(text);

    /* An instance without braces at the deepest level is fine (it opens no block). */
    size_t size = 64 * 10 + 256;
    text = malloc(size);
    assert_non_null(text);
    size_t used = (size_t)snprintf(text, size, "material m lambertian 1 1 1\ngroup g material m {\nsphere 0 0 0 1\n}\n");
    for (int i = 0; i < 64; i++)
        used += (size_t)snprintf(text + used, size - used, "group {\n");
    used += (size_t)snprintf(text + used, size - used, "instance g\n");
    for (int i = 0; i < 64; i++)
        used += (size_t)snprintf(text + used, size - used, "}\n");
    parse_ok(text, NULL, &s);
    assert_int_equal(s.instance_count, 2);
    scene_free(&s);
    free(text);
}

static void test_include_inside_a_block(void **state)
{
    write_text(state, "parts/transforms.txt", "rotate 0 0 1 90\n");
    write_text(state, "parts/shapes.txt", "sphere 0 0 0 1\nquad 0 0 0 1 0 0 0 1 0 m\n");
    write_text(state, "top.txt",
               "material m lambertian 1 1 1\n"
               "group material m {\n"
               "    include \"parts/transforms.txt\"   # transforms may come from an include\n"
               "    translate 5 0 0\n"
               "    include \"parts/shapes.txt\"\n"
               "    sphere 1 1 1 1\n"
               "}\n");
    scene s;
    load_file_ok(state, "top.txt", NULL, &s);
    assert_int_equal(s.sphere_count, 0);                   /* in a block: not plain spheres */
    assert_int_equal(s.object_count, 1);
    assert_int_equal(s.objects[0].shape_count, 3);
    assert_int_equal(s.shapes[0].type, SHAPE_SPHERE);
    assert_int_equal(s.shapes[1].type, SHAPE_QUAD);
    assert_int_equal(s.shapes[1].material, 0);
    assert_vector_equal(s.shapes[2].points[0], 1, 1, 1);
    assert_int_equal(s.instance_count, 1);
    assert_maps(&s.instances[0], 1, 0, 0, 5, 1, 0);
    scene_free(&s);

    /* A shape in the include ends the transforms of the includer's block. */
    write_text(state, "late.txt", "material m lambertian 1 1 1\ngroup material m {\n  include \"parts/shapes.txt\"\n"
                                  "  translate 1 0 0\n}\n");
    assert_file_error(state, "late.txt", NULL, "%s/late.txt:4:3: ", "transforms come first in a group");

    /* Each file closes the blocks it opens. */
    write_text(state, "opens.txt", "group {\n");
    write_text(state, "open-in-include.txt", "include \"opens.txt\"\n}\n");
    assert_file_error(state, "open-in-include.txt", NULL, "%s/opens.txt:1:1: ",
                      "this group is never closed (expected a '}' on a line of its own before the end of %s/opens.txt)");
    write_text(state, "closes.txt", "# closes its includer's block\n}\n");
    write_text(state, "close-in-include.txt", "volume 1 1 1 1 {\n  include \"closes.txt\"\n}\n");
    assert_file_error(state, "close-in-include.txt", NULL, "%s/closes.txt:2:1: ",
                      "unexpected '}': this file opened no block (the open volume was opened at "
                      "%s/close-in-include.txt:1:1; a block must be closed in the file that opens it)");
    /* An include inside an instance block may hold transforms only. */
    write_text(state, "shift.txt", "translate 0 0 3\n");
    write_text(state, "instanced.txt", "material m lambertian 1 1 1\ngroup g material m {\n  sphere 0 0 0 1\n}\n"
                                       "instance g {\n  include \"shift.txt\"\n}\n");
    load_file_ok(state, "instanced.txt", NULL, &s);
    assert_int_equal(s.instance_count, 2);
    assert_maps(&s.instances[1], 0, 0, 0, 0, 0, 3);
    scene_free(&s);
    write_text(state, "bad-instanced.txt", "material m lambertian 1 1 1\ngroup g material m {\n}\n"
                                           "instance g {\n  include \"parts/shapes.txt\"\n}\n");
    assert_file_error(state, "bad-instanced.txt", NULL, "%s/parts/shapes.txt:1:1: ", "inside an instance block");
}

/* ------------------------------------------------------------------ lights, ambient, phong */

static void test_lights_defaults(void **state)
{
    (void)state;
    scene s;
    parse_ok("", NULL, &s);
    assert_int_equal(s.light_count, 0);
    assert_null(s.lights);
    assert_vector_equal(s.ambient, 0.03, 0.03, 0.03);
    scene_free(&s);

    parse_ok("light point 1 2 3\n"
             "light spot 1 1 1 at 1 1 -3\n"
             "light sun 0 -1 0\n", NULL, &s);
    assert_int_equal(s.light_count, 3);
    const scene_light *point = &s.lights[0], *spot = &s.lights[1], *sun = &s.lights[2];
    assert_int_equal(point->type, SCENE_LIGHT_POINT);
    assert_vector_equal(point->position, 1, 2, 3);
    assert_vector_equal(point->color, 1, 1, 1);                 /* white, intensity 1 */
    assert_int_equal(point->falloff, FALLOFF_INVERSE_SQUARE);
    assert_vector_equal(point->attenuation, 1, 0, 0);           /* unused, as scene_light_defaults */
    assert_int_equal(spot->type, SCENE_LIGHT_SPOT);
    assert_vector_equal(spot->position, 1, 1, 1);
    assert_vector_equal(spot->direction, 0, 0, -1);             /* normalize(at - position) */
    assert_double_equal(spot->spot_inner_degrees, 25, 0);
    assert_double_equal(spot->spot_outer_degrees, 30, 0);
    assert_int_equal(spot->falloff, FALLOFF_INVERSE_SQUARE);
    assert_vector_equal(spot->color, 1, 1, 1);
    assert_int_equal(sun->type, SCENE_LIGHT_SUN);
    assert_vector_equal(sun->direction, 0, -1, 0);              /* the direction light travels */
    assert_vector_equal(sun->position, 0, 0, 0);
    assert_double_equal(sun->sun_angle_degrees, 0.53, 1e-7);
    assert_vector_equal(sun->color, 1, 1, 1);
    /* Every default is scene_light_defaults' own. */
    scene_light expected = scene_light_defaults(SCENE_LIGHT_SUN);
    assert_memory_equal(sun, &expected, sizeof expected);
    expected = scene_light_defaults(SCENE_LIGHT_POINT);
    memcpy(expected.position, point->position, sizeof expected.position);
    assert_memory_equal(point, &expected, sizeof expected);
    scene_free(&s);
}

static void test_light_clauses(void **state)
{
    (void)state;
    scene s;
    parse_ok("light point 1 2 3 color 1 0.5 0.25 intensity 4 falloff polynomial 1 0.09 0.032\n"
             "light spot 0 5 0 at 0 0 0 cone 10 20 falloff inverse_square intensity 2\n"
             "light sun 1 -1 0 angle 2 color 0.5 0.5 0.5   # any order\n"
             "light sun 3 -4 0 intensity 0 angle 0\n"
             "light spot 0 1 0 at 0 0 0 cone 0 0\n"
             "light spot 0 1 0 at 2 1 0 cone 89.5 89.5 color 2 0 0\n"
             "light point 0 0 0 falloff polynomial 0 0 1 color 0 0 0\n"
             "light point 0 0 0 falloff polynomial 1e-3 0 0\n"
             "light sun 0 -1e-30 0\n", NULL, &s);
    assert_int_equal(s.light_count, 9);
    const scene_light *l = s.lights;
    /* color x intensity is what the scene stores. */
    assert_vector_equal(l[0].color, 4, 2, 1);
    assert_int_equal(l[0].falloff, FALLOFF_POLYNOMIAL);
    assert_vector_equal(l[0].attenuation, 1, 0.09, 0.032);
    assert_vector_equal(l[1].direction, 0, -1, 0);
    assert_double_equal(l[1].spot_inner_degrees, 10, 0);
    assert_double_equal(l[1].spot_outer_degrees, 20, 0);
    assert_int_equal(l[1].falloff, FALLOFF_INVERSE_SQUARE);
    assert_vector_equal(l[1].color, 2, 2, 2);
    assert_vector_equal(l[2].direction, sqrt(0.5), -sqrt(0.5), 0);   /* normalised */
    assert_double_equal(l[2].sun_angle_degrees, 2, 0);
    assert_vector_equal(l[2].color, 0.5, 0.5, 0.5);
    assert_vector_equal(l[3].direction, 0.6, -0.8, 0);
    assert_vector_equal(l[3].color, 0, 0, 0);                  /* intensity 0 is allowed */
    assert_double_equal(l[3].sun_angle_degrees, 0, 0);
    assert_double_equal(l[4].spot_inner_degrees, 0, 0);
    assert_double_equal(l[4].spot_outer_degrees, 0, 0);
    assert_double_equal(l[5].spot_outer_degrees, 89.5, 0);
    assert_vector_equal(l[5].direction, 1, 0, 0);
    assert_vector_equal(l[5].color, 2, 0, 0);
    assert_vector_equal(l[6].attenuation, 0, 0, 1);
    assert_vector_equal(l[6].color, 0, 0, 0);
    assert_int_equal(l[7].falloff, FALLOFF_POLYNOMIAL);
    assert_double_equal(l[7].attenuation[0], 1e-3, 1e-10);
    assert_vector_equal(l[8].direction, 0, -1, 0);             /* tiny but not zero */
    scene_free(&s);
}

static void test_light_expressions_and_sweep(void **state)
{
    (void)state;
    const char *text = "set t 0\n"
                       "set cone 15\n"
                       "light point (4*cos($t)) 5 (4*sin($t)) intensity ($t + 1)\n"
                       "light spot 0 $cone 0 at (2*$cone) 0 0 cone ($cone/3) $cone color (0.5) 1 ($t)\n";
    scene s;
    parse_ok(text, NULL, &s);
    assert_vector_equal(s.lights[0].position, 4, 5, 0);
    assert_vector_equal(s.lights[0].color, 1, 1, 1);
    assert_vector_equal(s.lights[1].position, 0, 15, 0);
    assert_vector_equal(s.lights[1].direction, 30 / sqrt(30 * 30 + 15 * 15), -15 / sqrt(30 * 30 + 15 * 15), 0);
    assert_double_equal(s.lights[1].spot_inner_degrees, 5, 1e-6);
    assert_double_equal(s.lights[1].spot_outer_degrees, 15, 0);
    assert_vector_equal(s.lights[1].color, 0.5, 1, 0);
    scene_free(&s);

    /* A sweep: -D moves the light a quarter turn, and the intensity with it. */
    const scene_define defines[] = {{.name = "t", .value = "pi/2"}};
    scene_parse_options options = options_with_defines(defines, 1);
    parse_ok(text, &options, &s);
    assert_vector_equal(s.lights[0].position, 0, 5, 4);
    double intensity = 3.14159265358979323846 / 2 + 1;
    assert_vector_equal(s.lights[0].color, intensity, intensity, intensity);
    assert_vector_equal(s.lights[1].color, 0.5, 1, 3.14159265358979323846 / 2);
    scene_free(&s);

    const scene_define half[] = {{.name = "t", .value = "pi"}};
    options = options_with_defines(half, 1);
    parse_ok(text, &options, &s);
    assert_vector_equal(s.lights[0].position, -4, 5, 0);
    scene_free(&s);

    assert_parse_error("light point $x 0 0", "s.txt:1:13: ", "undefined variable $x");
    assert_parse_error("light point (1/0) 0 0", "s.txt:1:15: ", "division by zero");
    assert_parse_error("light point 0 0 0 intensity 2*3", "s.txt:1:29: ", "write an expression in parentheses");
}

static void test_light_errors(void **state)
{
    (void)state;
    /* The type and the required arguments. */
    assert_parse_error("light", "s.txt:1:6: ", "expected a light type (point, spot or sun), found end of line");
    assert_parse_error("light area 0 0 0", "s.txt:1:7: ", "expected a light type (point, spot or sun), found 'area'");
    assert_parse_error("light Point 0 0 0", "s.txt:1:7: ", "found 'Point'");
    assert_parse_error("light point 0 0", "s.txt:1:16: ",
                       "expected a number for the point light's position z, found end of line");
    assert_parse_error("light spot", "s.txt:1:11: ", "expected a number for the spot light's position x");
    assert_parse_error("light spot 0 5 0", "s.txt:1:17: ",
                       "expected 'at' and the point the spot light shines at after its position, found end of line");
    assert_parse_error("light spot 0 5 0 color 1 1 1", "s.txt:1:18: ", "expected 'at' and the point the spot light "
                       "shines at after its position, found 'color'");
    assert_parse_error("light spot 0 5 0 at 0 0", "s.txt:1:24: ",
                       "expected a number for the spot light's at z, found end of line");
    assert_parse_error("light spot 0 5 0 at 0 5 0", "s.txt:1:21: ",
                       "the spot light's at is its position (0 5 0), so it has no direction");
    assert_parse_error("light sun", "s.txt:1:10: ", "expected a number for the sun's direction x, found end of line");
    assert_parse_error("light sun 0 0 0", "s.txt:1:11: ", "the sun's direction (0 0 0) has zero length");
    assert_parse_error("light sun (0) (1-1) -0", "s.txt:1:11: ", "has zero length");
    assert_parse_error("light point nan 0 0", "s.txt:1:13: ", "NaN and infinity are not allowed");
    assert_parse_error("light point 1e39 0 0", "s.txt:1:13: ", "too large for the renderer's 32-bit floats");
    assert_parse_error("light sun 0 -1e39 0", "s.txt:1:13: ", "too large for the renderer's 32-bit floats");

    /* Colour and intensity. */
    assert_parse_error("light point 0 0 0 color 1 -1 1", "s.txt:1:27: ",
                       "the green component of the point light's color must be >= 0, found -1$");
    assert_parse_error("light sun 0 -1 0 color 1 1", "s.txt:1:27: ",
                       "expected a number for the blue component of the sun's color, found end of line");
    assert_parse_error("light point 0 0 0 intensity -2", "s.txt:1:29: ",
                       "the point light's intensity must be >= 0, found -2$");
    assert_parse_error("light spot 0 1 0 at 0 0 0 intensity", "s.txt:1:36: ",
                       "expected a number for the spot light's intensity, found end of line");
    assert_parse_error("light point 0 0 0 color 10 1 1 intensity 1e38", "s.txt:1:42: ",
                       "the point light's color x intensity is 1e+39, too large for the renderer's 32-bit floats");

    /* Spot cone and sun angle. */
    assert_parse_error("light spot 0 5 0 at 0 0 0 cone -1 20", "s.txt:1:32: ",
                       "the spot light's inner cone angle must be from 0 up to (not including) 90 degrees, found -1$");
    assert_parse_error("light spot 0 5 0 at 0 0 0 cone 10 90", "s.txt:1:35: ",
                       "the spot light's outer cone angle must be from 0 up to (not including) 90 degrees, found 90$");
    assert_parse_error("light spot 0 5 0 at 0 0 0 cone 90 95", "s.txt:1:32: ", "inner cone angle must be from 0");
    assert_parse_error("light spot 0 5 0 at 0 0 0 cone 40 30", "s.txt:1:35: ",
                       "the spot light's cone must have 0 <= inner <= outer < 90 degrees, found inner 40 and outer 30$");
    assert_parse_error("light spot 0 5 0 at 0 0 0 cone 10", "s.txt:1:34: ",
                       "expected a number for the spot light's outer cone angle, found end of line");
    assert_parse_error("light sun 0 -1 0 angle 90", "s.txt:1:24: ",
                       "the sun's angle must be from 0 up to (not including) 90 degrees, found 90$");
    assert_parse_error("light sun 0 -1 0 angle -0.5", "s.txt:1:24: ", "found -0.5$");
    assert_parse_error("light sun 0 -1 0 angle", "s.txt:1:23: ", "expected a number for the sun's angle, found end of line");

    /* Falloff. */
    assert_parse_error("light point 0 0 0 falloff linear", "s.txt:1:27: ",
                       "expected a falloff for the point light (inverse_square, or polynomial C L Q), found 'linear'");
    assert_parse_error("light point 0 0 0 falloff", "s.txt:1:26: ", "expected a falloff for the point light");
    assert_parse_error("light point 0 0 0 falloff 2", "s.txt:1:27: ", "found '2'");
    assert_parse_error("light point 0 0 0 falloff polynomial 0 0 0", "s.txt:1:27: ",
                       "the terms of the point light's polynomial falloff must not all be 0");
    assert_parse_error("light spot 0 1 0 at 0 0 0 falloff polynomial 1e-50 0 0", "s.txt:1:35: ", "must not all be 0");
    assert_parse_error("light point 0 0 0 falloff polynomial 1 -1 0", "s.txt:1:40: ",
                       "the linear term of the point light's polynomial falloff must be >= 0, found -1$");
    assert_parse_error("light point 0 0 0 falloff polynomial 1 0", "s.txt:1:41: ",
                       "expected a number for the quadratic term of the point light's polynomial falloff, found end "
                       "of line");
    assert_parse_error("light point 0 0 0 falloff polynomial 1e39 0 0", "s.txt:1:38: ", "too large");

    /* Clauses that the type does not take, unknown and repeated clauses, extra tokens. */
    assert_parse_error("light point 0 0 0 cone 10 20", "s.txt:1:19: ",
                       "unknown point light clause 'cone' (expected color, intensity, falloff or group)");
    assert_parse_error("light point 0 0 0 angle 1", "s.txt:1:19: ", "unknown point light clause 'angle'");
    assert_parse_error("light sun 0 -1 0 falloff inverse_square", "s.txt:1:18: ",
                       "unknown sun light clause 'falloff' (expected color, intensity, angle or group)");
    assert_parse_error("light sun 0 -1 0 cone 1 2", "s.txt:1:18: ", "unknown sun light clause 'cone'");
    assert_parse_error("light spot 0 5 0 at 0 0 0 angle 1", "s.txt:1:27: ",
                       "unknown spot light clause 'angle' (expected color, intensity, cone, falloff or group)");
    assert_parse_error("light spot 0 5 0 at 0 0 0 at 1 1 1", "s.txt:1:27: ", "unknown spot light clause 'at'");
    assert_parse_error("light point 0 0 0 2", "s.txt:1:19: ", "unknown point light clause '2'");
    assert_parse_error("light point 0 0 0 colour 1 1 1", "s.txt:1:19: ", "unknown point light clause 'colour'");
    assert_parse_error("light point 0 0 0 intensity 1 intensity 2", "s.txt:1:31: ",
                       "point light clause 'intensity' given twice in one statement (first at column 19)");
    assert_parse_error("light point 0 0 0 color 1 1 1 falloff inverse_square color 1 1 1", "s.txt:1:54: ",
                       "clause 'color' given twice");
    assert_parse_error("light spot 0 5 0 at 0 0 0 cone 1 2 cone 3 4", "s.txt:1:36: ", "clause 'cone' given twice");
    assert_parse_error("light sun 0 -1 0 angle 1 angle 1", "s.txt:1:26: ", "clause 'angle' given twice");
    assert_parse_error("light point 0 0 0 falloff inverse_square falloff inverse_square", "s.txt:1:42: ",
                       "clause 'falloff' given twice");
}

static void test_lights_only_at_the_top_level(void **state)
{
    (void)state;
    assert_parse_error("group {\n    light point 0 0 0\n}\n", "s.txt:2:5: ",
                       "lights go at the top level of a scene, not inside a group (this light is inside the group "
                       "opened at s.txt:1:1)");
    assert_parse_error("material m lambertian 1 1 1\ngroup g material m {\n  group {\n    light sun 0 -1 0\n  }\n}\n",
                       "s.txt:4:5: ", "lights go at the top level of a scene, not inside a group");
    assert_parse_error("volume 1 1 1 1 {\n  light sun 0 -1 0\n}\n", "s.txt:2:3: ",
                       "lights go at the top level of a scene, not inside a group (this light is inside the volume "
                       "opened at s.txt:1:1)");
    assert_parse_error("material m lambertian 1 1 1\ngroup g {\n  sphere 0 0 0 1 m\n}\ninstance g {\n\tlight point 0 0 0\n}\n",
                       "s.txt:6:2: ", "lights go at the top level of a scene, not inside a group (this light is "
                       "inside the instance block opened at s.txt:5:1)");
    /* Even a broken light statement says where lights go first. */
    assert_parse_error("group {\n light\n}\n", "s.txt:2:2: ", "lights go at the top level");

    /* After a block closes, the top level takes lights again; they do not end a block's
     * transforms because they are never in one. */
    scene s;
    parse_ok("material m lambertian 1 1 1\nlight point 0 9 0\ngroup {\n  sphere 0 0 0 1 m\n}\nlight sun 0 -1 0\n",
             NULL, &s);
    assert_int_equal(s.light_count, 2);
    assert_int_equal(s.lights[1].type, SCENE_LIGHT_SUN);
    scene_free(&s);
}

static void test_light_in_an_included_file(void **state)
{
    write_text(state, "lights.txt", "light point 0 5 0 intensity 10\n");
    write_text(state, "top.txt", "include \"lights.txt\"\nlight sun 0 -1 0\n");
    scene s;
    load_file_ok(state, "top.txt", NULL, &s);
    assert_int_equal(s.light_count, 2);
    assert_vector_equal(s.lights[0].color, 10, 10, 10);
    scene_free(&s);
    /* Included inside a group, the light is inside the group. */
    write_text(state, "in-group.txt", "group {\n  include \"lights.txt\"\n}\n");
    assert_file_error(state, "in-group.txt", NULL, "%s/lights.txt:1:1: ",
                      "lights go at the top level of a scene, not inside a group (this light is inside the group "
                      "opened at %s/in-group.txt:1:1)");
}

static void test_ambient(void **state)
{
    (void)state;
    scene s;
    parse_ok("ambient 0.1 0.2 0.3", NULL, &s);
    assert_vector_equal(s.ambient, 0.1, 0.2, 0.3);
    scene_free(&s);

    /* The last one wins; numbers are expressions; 0 and more than 1 are fine; it may stand
     * in a block (it is global, like camera). */
    parse_ok("set a 0.25\nambient 1 1 1\nambient (2*$a) $a 0   # dim\n", NULL, &s);
    assert_vector_equal(s.ambient, 0.5, 0.25, 0);
    scene_free(&s);
    parse_ok("group {\n  ambient 2 0 0\n}\n", NULL, &s);
    assert_vector_equal(s.ambient, 2, 0, 0);
    scene_free(&s);

    assert_parse_error("ambient", "s.txt:1:8: ",
                       "expected a number for the red component of the ambient colour, found end of line");
    assert_parse_error("ambient 0.1 0.2", "s.txt:1:16: ",
                       "expected a number for the blue component of the ambient colour, found end of line");
    assert_parse_error("ambient 0 -1 0", "s.txt:1:11: ", "the green component of the ambient colour must be >= 0, "
                       "found -1$");
    assert_parse_error("ambient 1 1 1 1", "s.txt:1:15: ", "unexpected '1' after the ambient colour (expected end of line)");
    assert_parse_error("ambient 1 1 1 intensity 2", "s.txt:1:15: ", "unexpected 'intensity' after the ambient colour");
    assert_parse_error("ambient nan 0 0", "s.txt:1:9: ", "NaN and infinity are not allowed");
    assert_parse_error("ambient 1e39 0 0", "s.txt:1:9: ", "too large for the renderer's 32-bit floats");
    assert_parse_error("ambient @tex 0 0", "s.txt:1:9: ", "expected a number for the red component of the ambient");
    /* A transform may not follow it in a block: it counts as content. */
    assert_parse_error("group {\n  ambient 0 0 0\n  translate 1 0 0\n}\n", "s.txt:3:3: ", "transforms come first");
}

static void test_material_phong_and_specular(void **state)
{
    (void)state;
    scene s;
    parse_ok("texture t noise 2\n"
             "material a lambertian 0.5 0.5 0.5 phong 64 specular 0.1 0.2 0.3\n"
             "material b metal 0.9 0.8 0.7 specular 1 1 1 fuzz 0.1 phong 8 normal_map \"n.png\"\n"
             "material c lambertian 0.5 0.5 0.5\n"
             "material d metal 1 1 1 phong (2^4)\n"
             "material e lambertian @t specular 0 0 0\n"
             "material f metal @t normal_map \"n.png\" specular 0.5 0.5 0.5\n"
             "material g lambertian 1 1 1 phong 1e-3\n"
             "material h dielectric 1.5\n"
             "material i emissive 1 1 1\n", NULL, &s);
    assert_int_equal(s.material_count, 9);
    const scene_material *m = s.materials;
    assert_double_equal(m[0].phong_exponent, 64, 0);
    assert_vector_equal(m[0].specular, 0.1, 0.2, 0.3);
    assert_true(m[0].specular_set);
    assert_int_equal(m[1].type, MATERIAL_METAL);
    assert_double_equal(m[1].phong_exponent, 8, 0);
    assert_vector_equal(m[1].specular, 1, 1, 1);
    assert_true(m[1].specular_set);
    assert_double_equal(m[1].fuzz, 0.1, 1e-7);
    assert_int_equal(m[1].normal_map, 0);
    /* Left out: phong 0 (the renderer's default 32) and no specular (its per-type default). */
    assert_double_equal(m[2].phong_exponent, 0, 0);
    assert_false(m[2].specular_set);
    assert_vector_equal(m[2].specular, 0, 0, 0);
    assert_double_equal(m[3].phong_exponent, 16, 0);
    assert_false(m[3].specular_set);
    assert_int_equal(m[4].albedo_texture, 0);
    assert_true(m[4].specular_set);                            /* explicitly black */
    assert_vector_equal(m[4].specular, 0, 0, 0);
    assert_int_equal(m[5].normal_map, 0);
    assert_vector_equal(m[5].specular, 0.5, 0.5, 0.5);
    assert_double_equal(m[6].phong_exponent, 1e-3, 1e-10);
    for (int i = 7; i < 9; i++) {
        assert_double_equal(m[i].phong_exponent, 0, 0);
        assert_false(m[i].specular_set);
    }
    scene_free(&s);

    assert_parse_error("material m lambertian 1 1 1 phong 0", "s.txt:1:35: ",
                       "the phong exponent of material 'm' must be > 0, found 0$");
    assert_parse_error("material m metal 1 1 1 phong -1", "s.txt:1:30: ", "must be > 0, found -1$");
    assert_parse_error("material m lambertian 1 1 1 phong 1e-50", "s.txt:1:35: ",
                       "the phong exponent of material 'm' 1e-50 is too small for the renderer's 32-bit floats");
    assert_parse_error("material m lambertian 1 1 1 phong 1e39", "s.txt:1:35: ", "too large");
    assert_parse_error("material m lambertian 1 1 1 phong", "s.txt:1:34: ",
                       "expected a number for the phong exponent of material 'm', found end of line");
    assert_parse_error("material m lambertian 1 1 1 phong shiny", "s.txt:1:35: ", "found 'shiny'");
    assert_parse_error("material m metal 1 1 1 specular 0.5 1.5 0", "s.txt:1:37: ",
                       "the green component of the specular colour of material 'm' must be between 0 and 1, found 1.5$");
    assert_parse_error("material m lambertian 1 1 1 specular -0.1 0 0", "s.txt:1:38: ",
                       "the red component of the specular colour of material 'm' must be between 0 and 1");
    assert_parse_error("material m metal 1 1 1 specular 0.5 0.5", "s.txt:1:40: ",
                       "expected a number for the blue component of the specular colour of material 'm', found end "
                       "of line");
    assert_parse_error("material m metal 1 1 1 specular @t", "s.txt:1:33: ", "expected a number for the red component");
    assert_parse_error("material m lambertian 1 1 1 phong 2 phong 3", "s.txt:1:37: ",
                       "lambertian material clause 'phong' given twice in one statement (first at column 29)");
    assert_parse_error("material m metal 1 1 1 specular 1 1 1 specular 0 0 0", "s.txt:1:39: ",
                       "metal material clause 'specular' given twice");
    /* Dielectric and emissive materials take neither. */
    assert_parse_error("material g dielectric 1.5 phong 8", "s.txt:1:27: ",
                       "unknown dielectric material clause 'phong' (expected normal_map)");
    assert_parse_error("material l emissive 1 1 1 specular 1 1 1", "s.txt:1:27: ",
                       "unknown emissive material clause 'specular' (expected strength, one_sided or group)");
}

/* The example in docs/scene-format.md's light section, exactly. */
static void test_documented_light_example(void **state)
{
    (void)state;
    const char *text =
        "set t 0                                  # sweep with -D t=...\n"
        "ambient 0.02 0.02 0.03\n"
        "light sun 1 -2 -1 color 1 0.95 0.9 intensity 3 angle 0.53\n"
        "light point (4*cos($t)) 5 (4*sin($t)) color 1 0.8 0.6 intensity 60\n"
        "light spot 0 4 0 at 0 0 0 intensity 40 cone 20 30 falloff polynomial 1 0.09 0.032\n"
        "material red lambertian 0.8 0.2 0.1 phong 64 specular 0.2 0.2 0.2\n"
        "material gold metal 0.9 0.7 0.3 fuzz 0.1 phong 200\n"
        "sphere 0 0.5 0 0.5 red\n";
    scene s;
    parse_ok(text, NULL, &s);
    assert_int_equal(s.light_count, 3);
    assert_vector_equal(s.ambient, 0.02, 0.02, 0.03);
    assert_vector_equal(s.lights[0].direction, 1 / sqrt(6), -2 / sqrt(6), -1 / sqrt(6));
    assert_vector_equal(s.lights[0].color, 3, 2.85, 2.7);
    assert_vector_equal(s.lights[1].position, 4, 5, 0);
    assert_vector_equal(s.lights[1].color, 60, 48, 36);
    assert_int_equal(s.lights[2].falloff, FALLOFF_POLYNOMIAL);
    assert_vector_equal(s.lights[2].direction, 0, -1, 0);
    assert_double_equal(s.materials[0].phong_exponent, 64, 0);
    assert_true(s.materials[0].specular_set);
    assert_false(s.materials[1].specular_set);
    scene_free(&s);

    /* "-D t=pi/2 moves the point light a quarter turn, from (4, 5, 0) to (0, 5, 4)." */
    const scene_define defines[] = {{.name = "t", .value = "pi/2"}};
    scene_parse_options options = options_with_defines(defines, 1);
    parse_ok(text, &options, &s);
    assert_vector_equal(s.lights[1].position, 0, 5, 4);
    scene_free(&s);
}

/* ------------------------------------------------------------------ the documented scene-model example */

static void test_documented_scene_model_example(void **state)
{
    (void)state;
    /* The second example of docs/scene-format.md, kept in sync by hand. */
    const char *text =
        "# A wooden table with a glass ball on it, a second table behind it, and a puff of smoke.\n"
        "render size 640 360 spp 128 depth 16\n"
        "camera from 0 1.6 4 at 0 0.7 0 fov 40 shutter 0 1\n"
        "sky gradient 1 1 1  0.5 0.7 1.0 intensity 1\n"
        "\n"
        "texture light constant 0.9 0.9 0.9\n"
        "texture tiles checker 0.5 @light 0.2 0.2 0.2\n"
        "texture grain marble 8\n"
        "\n"
        "material floor lambertian @tiles\n"
        "material wood lambertian @grain\n"
        "material glass dielectric 1.5\n"
        "material lamp emissive 1 0.9 0.8 strength 8\n"
        "\n"
        "quad -10 0 10  20 0 0  0 0 -20 floor     # 20 x 20, facing up (u x v points up)\n"
        "sphere 0 6 0 1 lamp\n"
        "\n"
        "group table material wood {\n"
        "    group leg {\n"
        "        translate -0.5 0 -0.3\n"
        "        box -0.03 0 -0.03  0.03 0.7 0.03\n"
        "    }\n"
        "    instance leg {\n"
        "        translate 1 0 0\n"
        "    }\n"
        "    instance leg {\n"
        "        translate 0 0 0.6\n"
        "    }\n"
        "    instance leg {\n"
        "        translate 1 0 0.6\n"
        "    }\n"
        "    box -0.6 0.7 -0.4  0.6 0.75 0.4         # the top\n"
        "    sphere 0 0.95 0 0.2 glass\n"
        "}\n"
        "\n"
        "instance table {\n"
        "    rotate 0 1 0 30\n"
        "    translate 1.5 0 -2\n"
        "}\n"
        "\n"
        "volume 2 0.8 0.8 0.8 {\n"
        "    translate -1.5 0.5 -1\n"
        "    sphere 0 0 0 0.5\n"
        "}\n";
    scene s;
    parse_ok(text, NULL, &s);
    assert_int_equal(s.texture_count, 4);                  /* with the checker's hidden 0.2 0.2 0.2 */
    assert_int_equal(s.material_count, 4);
    assert_int_equal(s.materials[0].albedo_texture, 2);
    assert_int_equal(s.sphere_count, 1);
    /* Objects: the floor, a leg, the table's own shapes (top and ball), the smoke. */
    assert_int_equal(s.object_count, 4);
    assert_int_equal(s.objects[0].shape_count, 1);
    assert_int_equal(s.objects[1].shape_count, 6);
    assert_int_equal(s.objects[2].shape_count, 7);
    assert_int_equal(s.shape_count, 15);
    /* Instances: the floor; four legs and the table's shapes; all five again; the smoke. */
    assert_int_equal(s.instance_count, 12);
    assert_true(is_identity(&s.instances[0]));
    for (int i = 1; i <= 10; i++) {
        assert_int_equal(s.instances[i].object, i == 5 || i == 10 ? 2 : 1);
        assert_int_equal(s.instances[i].material, 1);
    }
    assert_maps(&s.instances[1], 0, 0, 0, -0.5, 0, -0.3);
    assert_maps(&s.instances[2], 0, 0, 0, 0.5, 0, -0.3);
    assert_maps(&s.instances[4], 0, 0, 0, 0.5, 0, 0.3);
    double c = cos(30 * 3.14159265358979323846 / 180), sn = sin(30 * 3.14159265358979323846 / 180);
    assert_maps(&s.instances[6], 0, 0, 0, 1.5 - 0.5 * c - 0.3 * sn, 0, -2 + 0.5 * sn - 0.3 * c);
    assert_true(s.instances[11].volume);
    assert_double_equal(s.instances[11].density, 2, 0);
    assert_maps(&s.instances[11], 0, 0, 0, -1.5, 0.5, -1);
    assert_double_equal(s.camera.shutter_close, 1, 0);
    scene_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_empty_text_gives_defaults),
        cmocka_unit_test(test_camera_clauses),
        cmocka_unit_test(test_render_clauses),
        cmocka_unit_test(test_sky),
        cmocka_unit_test(test_materials),
        cmocka_unit_test(test_spheres),
        cmocka_unit_test(test_comments_spacing_and_line_endings),
        cmocka_unit_test(test_number_forms),
        cmocka_unit_test(test_set_and_variables),
        cmocka_unit_test(test_variable_must_be_set_before_use),
        cmocka_unit_test(test_set_errors),
        cmocka_unit_test(test_expression_errors_have_scene_positions),
        cmocka_unit_test(test_bad_number_tokens),
        cmocka_unit_test(test_non_finite_numbers),
        cmocka_unit_test(test_value_ranges),
        cmocka_unit_test(test_integer_ranges),
        cmocka_unit_test(test_unknown_statement),
        cmocka_unit_test(test_unknown_clause),
        cmocka_unit_test(test_repeated_clause),
        cmocka_unit_test(test_missing_arguments),
        cmocka_unit_test(test_extra_tokens),
        cmocka_unit_test(test_material_names),
        cmocka_unit_test(test_camera_frame_is_checked_after_the_file),
        cmocka_unit_test(test_lexical_errors),
        cmocka_unit_test(test_binary_bytes),
        cmocka_unit_test(test_very_long_lines),
        cmocka_unit_test(test_many_spheres),
        cmocka_unit_test(test_define_overrides_set),
        cmocka_unit_test(test_define_used_without_set),
        cmocka_unit_test(test_define_unused_is_an_error),
        cmocka_unit_test(test_define_bad_value),
        scratch_test(test_load_file),
        scratch_test(test_unreadable_top_file),
        scratch_test(test_binary_file),
        scratch_test(test_include_relative_to_including_file),
        scratch_test(test_include_from_string_and_absolute_path),
        scratch_test(test_include_camera_position),
        scratch_test(test_missing_include),
        scratch_test(test_oversized_files),
        scratch_test(test_include_cycles),
        scratch_test(test_include_depth_limit),
        scratch_test(test_define_applies_across_includes),
        cmocka_unit_test(test_documented_example),
        cmocka_unit_test(test_textures),
        cmocka_unit_test(test_texture_errors),
        cmocka_unit_test(test_material_textures_and_normal_maps),
        cmocka_unit_test(test_pbr_material),
        cmocka_unit_test(test_sky_images_intensity_and_rotation),
        cmocka_unit_test(test_camera_shutter),
        cmocka_unit_test(test_top_level_shapes_form_one_world_object),
        cmocka_unit_test(test_box_expands_to_six_outward_quads),
        cmocka_unit_test(test_shape_errors),
        cmocka_unit_test(test_triangle_normals_and_uvs),
        cmocka_unit_test(test_triangle_normal_and_uv_errors),
        cmocka_unit_test(test_documented_triangle_example),
        cmocka_unit_test(test_transform_order),
        cmocka_unit_test(test_scale_matrix_and_rotate_forms),
        cmocka_unit_test(test_transform_errors),
        cmocka_unit_test(test_named_group_placed_again_shares_objects),
        cmocka_unit_test(test_material_inheritance),
        cmocka_unit_test(test_shapes_without_any_material),
        scratch_test(test_meshes),
        cmocka_unit_test(test_volumes),
        cmocka_unit_test(test_volume_boundary_must_be_closed),
        cmocka_unit_test(test_instance_forms_and_errors),
        cmocka_unit_test(test_braces),
        cmocka_unit_test(test_nesting_limit),
        scratch_test(test_include_inside_a_block),
        cmocka_unit_test(test_documented_scene_model_example),
        cmocka_unit_test(test_lights_defaults),
        cmocka_unit_test(test_light_clauses),
        cmocka_unit_test(test_light_expressions_and_sweep),
        cmocka_unit_test(test_light_errors),
        cmocka_unit_test(test_lights_only_at_the_top_level),
        scratch_test(test_light_in_an_included_file),
        cmocka_unit_test(test_ambient),
        cmocka_unit_test(test_material_phong_and_specular),
        cmocka_unit_test(test_documented_light_example),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
