/* test_render_tiles.c: images rendered in tiles (render_job.h, "Tiles") are the untiled
 * render bit for bit, every channel: R, G, B, samples, the AOVs, variance and light group
 * layers, with and without adaptive sampling (whose 3x3 rule needs margins round each
 * tile), tiled by a small forced --memory-budget and by a device side lowered with the
 * RTSPHERES_TEST_MAX_TEXTURE_SIZE hook; an image that fits is not tiled; the tiles are
 * reported; the output's metadata sums the tiles. Rendered on the device, tiny images. */
#include "image_io.h"
#include "merge.h"
#include "metadata_keys.h"
#include "render_job.h"
#include "support.h"

#include <dirent.h>
#include <unistd.h>

static const char *const scene_text = "render size 40 24 spp 4 depth 4 seed 7\n"
                                      "camera from 0 1 4 at 0 0.4 0 up 0 1 0 fov 45\n"
                                      "sky gradient 0.05 0.05 0.08  0.3 0.4 0.6 group sky\n"
                                      "material floor lambertian 0.6 0.6 0.6\n"
                                      "material clay lambertian 0.75 0.35 0.25\n"
                                      "material metal metal 0.8 0.8 0.9 fuzz 0.1\n"
                                      "quad -6 0 -6  0 0 12  12 0 0  floor\n"
                                      "sphere -0.6 0.5 0 0.5 clay\n"
                                      "sphere 0.6 0.5 0 0.5 metal\n"
                                      "light point -1.5 2.5 1.5 intensity 6 group key\n";

/* What the callbacks saw of one job. */
typedef struct tiles_seen {
    int planned;                 /* tiles_planned calls */
    int columns, rows;
    char reason[256];
} tiles_seen;

static void note_tiles(void *user, const render_job_image *image, int columns, int rows, int tile_width,
                       int tile_height, const char *reason)
{
    (void)image, (void)tile_width, (void)tile_height;
    tiles_seen *seen = user;
    seen->planned++;
    seen->columns = columns;
    seen->rows = rows;
    snprintf(seen->reason, sizeof seen->reason, "%s", reason);
}

/* Renders the scene at scene_path to output on context with the options of adaptive
 * (a noise threshold or none) and budget (0: the default); fills *seen. */
static void render_to(gpu_context *context, const char *scene_path, const char *output, bool adaptive,
                      uint64_t budget, tiles_seen *seen)
{
    render_job job = render_job_defaults();
    job.scene_path = scene_path;
    job.output = output;
    job.aovs = true;
    job.variance = true;
    job.light_groups = true;
    job.memory_budget = budget;
    if (adaptive) {
        job.samples_per_pixel = 32;
        job.tracer.noise_threshold = 0.2f;
        job.tracer.min_spp = 4;
    }
    memset(seen, 0, sizeof *seen);
    render_job_callbacks callbacks = {.user = seen, .tiles_planned = note_tiles};
    rt_error error = {{0}};
    rt_status status = render_job_run(context, &job, &callbacks, NULL, &error);
    if (status != RT_OK)
        fail_msg("rendering %s: %s", output, error.message);
}

/* Checks that the EXRs a and b hold the same channels, names and place, every float
 * bit for bit, and the same sample total in their metadata. */
static void same_exr(const char *a, const char *b)
{
    rt_image first, second;
    merge_metadata first_metadata, second_metadata;
    rt_error error = {{0}};
    if (merge_read_part(a, &first, &first_metadata, &error) != RT_OK
        || merge_read_part(b, &second, &second_metadata, &error) != RT_OK)
        fail_msg("reading: %s", error.message);
    assert_int_equal(first.width, second.width);
    assert_int_equal(first.height, second.height);
    assert_int_equal(first.channels, second.channels);
    assert_int_equal(first.x, second.x);
    assert_int_equal(first.y, second.y);
    for (int c = 0; c < first.channels; c++)
        assert_string_equal(first.channel_names[c], second.channel_names[c]);
    size_t floats = (size_t)first.width * first.height * first.channels;
    for (size_t i = 0; i < floats; i++)
        if (memcmp(&first.pixels[i], &second.pixels[i], sizeof(float)) != 0)
            fail_msg("%s and %s differ at pixel %zu channel %s: %.9g and %.9g", a, b, i / first.channels,
                     first.channel_names[i % first.channels], first.pixels[i], second.pixels[i]);
    assert_string_equal(first_metadata.scene_hash, second_metadata.scene_hash);
    assert_int_equal(first_metadata.complete, second_metadata.complete);
    assert_true(first_metadata.complete);
    char first_samples[32], second_samples[32];
    assert_int_equal(image_read_attribute(a, METADATA_KEY_SAMPLES_FINISHED, first_samples, sizeof first_samples,
                                          &error), RT_OK);
    assert_int_equal(image_read_attribute(b, METADATA_KEY_SAMPLES_FINISHED, second_samples, sizeof second_samples,
                                          &error), RT_OK);
    assert_string_equal(first_samples, second_samples);
    image_free(&first);
    image_free(&second);
}

/* A budget of a few tiles: four light group layers, AOVs and variance make the 40x24
 * render about 700 KiB. */
#define SMALL_BUDGET (400u * 1024u)

/* Tiled by the budget = untiled, plain and adaptive; the untiled one was not tiled, and
 * the default budget does not tile an image this small. */
static void budget_tiles_are_the_untiled_render(void **state)
{
    scratch *s = *state;
    char scene_path[600], untiled[600], tiled[600];
    snprintf(scene_path, sizeof scene_path, "%s", write_file(s, "scene.txt", scene_text));
    snprintf(untiled, sizeof untiled, "%s", in_scratch(s, "untiled.exr"));
    snprintf(tiled, sizeof tiled, "%s", in_scratch(s, "tiled.exr"));
    for (int adaptive = 0; adaptive < 2; adaptive++) {
        tiles_seen seen;
        render_to(gpu_fixture_context, scene_path, untiled, adaptive, 0, &seen);
        assert_int_equal(seen.planned, 0);
        render_to(gpu_fixture_context, scene_path, tiled, adaptive, SMALL_BUDGET, &seen);
        assert_int_equal(seen.planned, 1);
        assert_true(seen.columns * seen.rows > 1);
        assert_non_null(strstr(seen.reason, "over the memory budget of 400 KiB"));
        same_exr(untiled, tiled);
    }
    /* Nothing of the spool or the temporary files is left beside the outputs. */
    int entries = 0;
    DIR *directory = opendir(s->directory);
    for (struct dirent *entry; (entry = readdir(directory)) != NULL;)
        entries += entry->d_name[0] != '.';
    closedir(directory);
    assert_int_equal(entries, 3);
}

/* A device side of 16 pixels (the test hook, read when the context is made) tiles the
 * 40x24 image into 3 x 2 tiles whatever the budget: the same image. */
static void device_side_tiles_are_the_untiled_render(void **state)
{
    scratch *s = *state;
    char scene_path[600], untiled[600], tiled[600];
    snprintf(scene_path, sizeof scene_path, "%s", write_file(s, "scene.txt", scene_text));
    snprintf(untiled, sizeof untiled, "%s", in_scratch(s, "untiled.exr"));
    snprintf(tiled, sizeof tiled, "%s", in_scratch(s, "tiled.exr"));
    tiles_seen seen;
    render_to(gpu_fixture_context, scene_path, untiled, false, 0, &seen);
    setenv("RTSPHERES_TEST_MAX_TEXTURE_SIZE", "16", 1);
    gpu_context *small = NULL;
    rt_error error = {{0}};
    rt_status status = gpu_create(NULL, &small, &error);
    unsetenv("RTSPHERES_TEST_MAX_TEXTURE_SIZE");
    if (status != RT_OK)
        fail_msg("%s", error.message);
    gpu_info info;
    gpu_get_info(small, &info);
    assert_int_equal(info.max_tile_side, 16);
    render_to(small, scene_path, tiled, false, 0, &seen);
    gpu_destroy(small);
    assert_int_equal(seen.planned, 1);
    assert_int_equal(seen.columns, 3);
    assert_int_equal(seen.rows, 2);
    assert_non_null(strstr(seen.reason, "larger than the device's 16 pixels a side"));
    same_exr(untiled, tiled);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        scratch_test(budget_tiles_are_the_untiled_render),
        scratch_test(device_side_tiles_are_the_untiled_render),
    };
    return cmocka_run_group_tests(tests, gpu_fixture_set_up, gpu_fixture_tear_down);
}
