/* fuzz_scene_parse.c: libFuzzer harness for the scene pipeline a render runs before the
 * GPU: text -> scene_load_string()/scene_load_file() -> pack_scene() (BVH build and
 * packing) -> camera_frame_compute() and a few CPU rays through the packed BVH.
 *
 * Input format (so that plain scene files are good seeds as they are):
 *   - Normally the whole input is the scene text, parsed with scene_load_string().
 *   - When the first byte is 0x01, the first line is a control line instead:
 *       byte 1        option bits: 1 = write the text to a file and use scene_load_file()
 *                     (so NUL bytes reach the parser), 2 = max_include_depth 2
 *       bytes 2..'\n' up to 8 defines "NAME=VALUE" separated by ';' (no '=': no value)
 *     and the scene text starts after the '\n'.
 *
 * Includes resolve against a private temporary directory made once at start-up, holding a
 * few small files (a valid one, one that includes another, a self-cycle, a bad one), so
 * `include "a.txt"` sometimes succeeds and the include machinery is exercised.
 *
 * Meshes and images are not read from disk (that needs the C++ loaders): after a
 * successful parse each one gets a small synthetic stand-in, so the packer sees a loaded
 * scene (fake_assets). Besides crashes and sanitizer reports, the harness aborts when the
 * documented contract breaks: a failed parse must leave the scene at scene_defaults()
 * with a message, a failed pack must say why, and a ray must never hit a primitive slot
 * that does not exist.
 *
 * Built by `make fuzz` (see the Makefile); run by tests/fuzz/run.sh. */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "camera.h"
#include "pack.h"
#include "packed_traverse.h"
#include "scene_parse.h"

#define MAX_DEFINES 8
#define OPTION_LOAD_FILE 1
#define OPTION_SHALLOW_INCLUDES 2

/* The private include directory and the paths the top-level text is given. */
static char include_directory[256];
static char string_source_name[300];
static char file_source_path[300];

/* Writes text to directory/name; aborts on failure, since the harness would be useless. */
static void write_fixture(const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", include_directory, name);
    FILE *file = fopen(path, "w");
    if (file == NULL || fputs(text, file) < 0 || fclose(file) != 0) {
        fprintf(stderr, "fuzz_scene_parse: cannot write %s\n", path);
        abort();
    }
}

/* Removes the include directory at exit, so repeated runs do not litter the temp dir. */
static void remove_fixtures(void)
{
    static const char *const names[] = {"a.txt", "b.txt", "loop.txt", "bad.txt", "sub/c.txt", "sub", "input.txt"};
    char path[512];
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", include_directory, names[i]);
        if (unlink(path) != 0)
            rmdir(path);
    }
    rmdir(include_directory);
}

/* libFuzzer calls this once before the first input: creates the include fixtures. */
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    const char *temporary = getenv("TMPDIR");
    snprintf(include_directory, sizeof include_directory, "%s/rtspheres-fuzz.XXXXXX",
             temporary != NULL && temporary[0] != '\0' ? temporary : "/tmp");
    if (mkdtemp(include_directory) == NULL) {
        perror("fuzz_scene_parse: mkdtemp");
        abort();
    }
    atexit(remove_fixtures);
    char sub[300];
    snprintf(sub, sizeof sub, "%s/sub", include_directory);
    mkdir(sub, 0700);
    write_fixture("a.txt", "set a_radius 0.5\nmaterial from_a lambertian 0.5 0.5 0.5\n"
                           "sphere 0 0 -2 $a_radius from_a\n");
    write_fixture("b.txt", "set b_value 2\ninclude \"a.txt\"\ncamera fov ($b_value * 20)\n");
    write_fixture("loop.txt", "include \"loop.txt\"\n");
    write_fixture("bad.txt", "sphere 0 0 0 -1 nothing\n");
    write_fixture("sub/c.txt", "include \"../b.txt\"\nsky constant 1 1 1\n");
    snprintf(string_source_name, sizeof string_source_name, "%s/string.txt", include_directory);
    snprintf(file_source_path, sizeof file_source_path, "%s/input.txt", include_directory);
    return 0;
}

/* True when a quoted string of the text (where include paths are) might name a device
 * or kernel file (/dev/zero, /dev/stdin, /proc/self/fd/0, ...): reading those blocks or
 * never ends, which is a property of the input, not a parser bug (the parser stops at
 * its file size limit, but only after reading that much), so such inputs are skipped. */
static bool names_special_files(const char *text, size_t length)
{
    static const char *const words[] = {"dev", "proc", "sys", "run"};
    size_t i = 0;
    while (i < length) {
        if (text[i++] != '"')
            continue;
        size_t start = i;
        while (i < length && text[i] != '"' && text[i] != '\n')
            i++;
        for (size_t w = 0; w < sizeof words / sizeof words[0]; w++)
            for (size_t k = start; k + 3 <= i; k++)
                if (memcmp(text + k, words[w], 3) == 0)
                    return true;
        i++;
    }
    return false;
}

/* Splits the control line "NAME=VALUE;NAME;..." (copied into storage, NUL-terminated)
 * into defines; returns how many. A part without '=' gets a NULL value, as a caller
 * passing a bare name would. */
static int split_defines(char *storage, scene_define *defines)
{
    int count = 0;
    char *part = storage;
    while (*part != '\0' && count < MAX_DEFINES) {
        char *end = strchr(part, ';');
        if (end != NULL)
            *end = '\0';
        char *equals = strchr(part, '=');
        if (equals != NULL)
            *equals = '\0';
        defines[count++] = (scene_define){.name = part, .value = equals != NULL ? equals + 1 : NULL};
        if (end == NULL)
            break;
        part = end + 1;
    }
    return count;
}

/* Checks the failure contract of scene_parse.h: an error status with a message, and the
 * output scene back at its defaults. */
static void check_failure(rt_status status, const rt_error *error, const scene *s)
{
    scene defaults;
    scene_defaults(&defaults);
    if (status != RT_ERROR_INPUT && status != RT_ERROR_RUNTIME)
        abort();
    if (error->message[0] == '\0' || memchr(error->message, '\0', sizeof error->message) == NULL)
        abort();
    if (memcmp(s, &defaults, sizeof defaults) != 0)
        abort();
}

/* Stands in for scene_load_assets(), which reads OBJ and image files through C++
 * libraries the harness does not link: every mesh becomes one triangle and every image a
 * 2x2 grey square (square, so sky boxes accept them). The packer then sees a loaded scene.
 * Returns false when memory runs out. */
static bool fake_assets(scene *s)
{
    for (int i = 0; i < s->mesh_count; i++) {
        scene_mesh *mesh = &s->meshes[i];
        if (mesh->positions != NULL)
            continue;
        static const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
        mesh->positions = malloc(sizeof positions);
        mesh->indices = malloc(3 * sizeof *mesh->indices);
        mesh->triangle_materials = malloc(sizeof *mesh->triangle_materials);
        if (mesh->positions == NULL || mesh->indices == NULL || mesh->triangle_materials == NULL)
            return false;
        memcpy(mesh->positions, positions, sizeof positions);
        for (uint32_t k = 0; k < 3; k++)
            mesh->indices[k] = k;
        mesh->triangle_materials[0] = mesh->default_material;
        mesh->vertex_count = 3;
        mesh->triangle_count = 1;
    }
    for (int i = 0; i < s->image_count; i++) {
        scene_image *image = &s->images[i];
        if (image->pixels != NULL)
            continue;
        image->pixels = malloc(2 * 2 * 4 * sizeof *image->pixels);
        if (image->pixels == NULL)
            return false;
        for (int k = 0; k < 2 * 2 * 4; k++)
            image->pixels[k] = 0.5f;
        image->width = image->height = 2;
    }
    return true;
}

/* Runs what a render does on the CPU with a parsed scene: pack it (BVHs included), make
 * the camera frame and trace a few primary rays through the packed BVH. */
static void pack_and_trace(scene *s)
{
    if (!fake_assets(s))
        return;
    packed_scene packed;
    rt_error error = {{0}};
    if (pack_scene(s, NULL, &packed, &error) != RT_OK) {
        if (error.message[0] == '\0')
            abort();
        return;
    }
    camera_frame frame;
    if (camera_frame_compute(&s->camera, s->render.width, s->render.height, &frame, &error) == RT_OK) {
        static const float film[][2] = {{0.5f, 0.5f}, {0, 0}, {1, 1}, {0.25f, 0.75f}};
        for (size_t i = 0; i < sizeof film / sizeof film[0]; i++) {
            float origin[3], direction[3];
            camera_frame_ray(&frame, film[i][0], film[i][1], 0.3f, -0.2f, origin, direction);
            packed_hit hit;
            if (packed_intersect_nearest(&packed, origin, direction, 0.5f, 1e30f, &hit) &&
                hit.primitive >= packed.primitive_count)
                abort();
        }
    }
    packed_scene_free(&packed);
}

/* libFuzzer's entry point: one input, one parse (and pack on success). */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (names_special_files((const char *)data, size))
        return 0;
    int options_bits = 0;
    scene_define defines[MAX_DEFINES];
    int define_count = 0;
    char *control = NULL;
    if (size > 0 && data[0] == 0x01) {
        const uint8_t *newline = memchr(data, '\n', size);
        size_t control_length = newline != NULL ? (size_t)(newline - data) : size;
        if (control_length >= 2)
            options_bits = data[1];
        /* The defines' text stops at a NUL too, as a C string from argv would. */
        size_t defines_length = control_length > 2 ? control_length - 2 : 0;
        control = malloc(defines_length + 1);
        if (control == NULL)
            return 0;
        memcpy(control, data + 2, defines_length);
        control[defines_length] = '\0';
        define_count = split_defines(control, defines);
        size_t skipped = newline != NULL ? control_length + 1 : size;
        data += skipped;
        size -= skipped;
    }

    scene_parse_options options = scene_parse_options_defaults();
    options.defines = defines;
    options.define_count = define_count;
    if (options_bits & OPTION_SHALLOW_INCLUDES)
        options.max_include_depth = 2;

    scene s;
    rt_error error = {{0}};
    rt_status status;
    if (options_bits & OPTION_LOAD_FILE) {
        FILE *file = fopen(file_source_path, "wb");
        if (file == NULL || (size > 0 && fwrite(data, 1, size, file) != size) || fclose(file) != 0)
            abort();
        status = scene_load_file(file_source_path, &options, &s, &error);
        /* A later string input must not be able to include this one's leftovers. */
        unlink(file_source_path);
    } else {
        /* An exactly sized copy: ASan then catches any read past the terminating NUL. */
        char *text = malloc(size + 1);
        if (text == NULL)
            abort();
        memcpy(text, data, size);
        text[size] = '\0';
        status = scene_load_string(text, string_source_name, &options, &s, &error);
        free(text);
    }

    if (status == RT_OK) {
        pack_and_trace(&s);
        scene_free(&s);
    } else {
        check_failure(status, &error, &s);
    }
    free(control);
    return 0;
}
