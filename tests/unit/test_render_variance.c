/* test_render_variance.c: the variance layers of render_options.variance (render.h),
 * rendered on the device: exact identities where every sample takes one of two values or
 * all channels are equal, and, over many seeds, that the variance of a pixel's mean it
 * predicts is not smaller than the spread the seeds really show (what the z test of
 * image_stat_diff.h relies on). */
#include "render.h"
#include "scene_parse.h"
#include "support.h"


/* Renders text with the given seed and options into *result (asserting success), with the
 * variance layers unless without_variance. */
static void render_text_with(const char *text, uint32_t seed, bool aovs, bool without_variance, render_result *result)
{
    scene s;
    rt_error error = {{0}};
    scene_parse_options parse = scene_parse_options_defaults();
    if (scene_load_string(text, "test.txt", &parse, &s, &error) != RT_OK)
        fail_msg("%s", error.message);
    s.render.seed = seed;
    render_options options = render_options_defaults();
    options.variance = !without_variance;
    options.aovs = aovs;
    if (render_scene(gpu_fixture_context, &s, &options, result, &error) != RT_OK)
        fail_msg("%s", error.message);
    scene_free(&s);
}

/* Renders text with the variance layers (render_text_with). */
static void render_text(const char *text, uint32_t seed, bool aovs, render_result *result)
{
    render_text_with(text, seed, aovs, false, result);
}

/* The index of the layer called name in result->aovs. */
static int layer(const render_result *result, const char *name)
{
    for (int c = 0; c < result->aovs.channels; c++)
        if (strcmp(result->aovs.channel_names[c], name) == 0)
            return c;
    fail_msg("no layer %s", name);
    return -1;
}

/* A black sphere against a constant sky of colour (0.9, 0.5, 0.25): each sample is 0 or
 * the sky (the black surface absorbs every path), so a pixel whose mean is m has the
 * variance m (sky - m) exactly, and the silhouette's pixels lie strictly between. */
static const char two_valued_scene[] = "render size 24 24 spp 16 depth 4 seed 1\n"
                                       "camera from 0 0 4 at 0.8 0 0 up 0 1 0 fov 30\n"
                                       "sky constant 0.9 0.5 0.25\n"
                                       "material black lambertian 0 0 0\n"
                                       "sphere 0 0 0 1 black\n";

static void two_valued_samples(void **state)
{
    (void)state;
    static const char *scene_text = two_valued_scene;
    static const float sky[3] = {0.9f, 0.5f, 0.25f};
    render_result result;
    render_text(scene_text, 1, false, &result);
    assert_int_equal(result.aovs.channels, 3);
    int layers[3] = {layer(&result, "variance.R"), layer(&result, "variance.G"), layer(&result, "variance.B")};
    int in_between = 0;
    for (int i = 0; i < 24 * 24; i++) {
        for (int c = 0; c < 3; c++) {
            double mean = result.image.pixels[4 * i + c];
            double variance = result.aovs.pixels[3 * i + layers[c]];
            assert_close(variance, mean * (sky[c] - mean), 1e-5);
            if (c == 0 && mean > 0.01 && mean < 0.89)
                in_between++;
        }
    }
    /* The silhouette crosses the frame: some pixels mix sky and sphere. */
    assert_true(in_between >= 8);
    image_free(&result.image);
    image_free(&result.aovs);
}

/* A grey scene: every sample has R = G = B = luminance, so the three variance layers equal
 * each other and variance.Y of the AOVs at every pixel. */
static void grey_channels_agree(void **state)
{
    (void)state;
    static const char scene_text[] = "render size 32 18 spp 8 depth 6 seed 1\n"
                                     "camera from 0 1 4 at 0 0.5 0 up 0 1 0 fov 40\n"
                                     "sky gradient 0.2 0.2 0.2  1 1 1\n"
                                     "material ground lambertian 0.5 0.5 0.5\n"
                                     "material ball metal 0.8 0.8 0.8 fuzz 0.3\n"
                                     "sphere 0 -1000 0 1000 ground\n"
                                     "sphere 0 0.5 0 0.5 ball\n";
    render_result result;
    render_text(scene_text, 3, true, &result);
    int r = layer(&result, "variance.R"), g = layer(&result, "variance.G"), b = layer(&result, "variance.B");
    int y = layer(&result, "variance.Y");
    double largest = 0;
    for (int i = 0; i < 32 * 18; i++) {
        const float *pixel = result.aovs.pixels + (size_t)i * result.aovs.channels;
        double tolerance = 1e-5 + 1e-4 * pixel[y];
        assert_close(pixel[r], pixel[y], tolerance);
        assert_close(pixel[g], pixel[y], tolerance);
        assert_close(pixel[b], pixel[y], tolerance);
        largest = fmax(largest, pixel[y]);
    }
    assert_true(largest > 1e-3);  /* the scene is noisy: the identity is not 0 = 0 */
    image_free(&result.image);
    image_free(&result.aovs);
}

#define SEEDS 24
#define WIDTH 32
#define HEIGHT 18

/* Over SEEDS renders of a noisy scene at 4 spp, the spread of each pixel's mean across
 * seeds against what the variance layer predicts for it, variance / (samples - 1),
 * summed over the image: the prediction may be larger (stratified samples) but not
 * smaller, beyond the noise of SEEDS seeds (about 2% on this sum). */
static void predicts_the_spread_of_seeds(void **state)
{
    (void)state;
    static const char scene_text[] = "render size 32 18 spp 4 depth 8 seed 1\n"
                                     "camera from 0 1.2 5 at 0 0.5 0 up 0 1 0 fov 35\n"
                                     "sky gradient 0.08 0.08 0.1  0.2 0.24 0.36\n"
                                     "material ground lambertian 0.5 0.5 0.48\n"
                                     "material red lambertian 0.75 0.2 0.15\n"
                                     "material light emissive 1 0.9 0.75 strength 6\n"
                                     "sphere 0 -1000 0 1000 ground\n"
                                     "sphere 0 0.5 0 0.5 red\n"
                                     "sphere -2.5 3.5 2.5 1.2 light\n";
    static double sum[WIDTH * HEIGHT][3], sum_squares[WIDTH * HEIGHT][3], predicted[WIDTH * HEIGHT][3];
    memset(sum, 0, sizeof sum);
    memset(sum_squares, 0, sizeof sum_squares);
    memset(predicted, 0, sizeof predicted);
    for (uint32_t seed = 1; seed <= SEEDS; seed++) {
        render_result result;
        render_text(scene_text, seed, false, &result);
        for (int i = 0; i < WIDTH * HEIGHT; i++)
            for (int c = 0; c < 3; c++) {
                double mean = result.image.pixels[4 * i + c];
                sum[i][c] += mean;
                sum_squares[i][c] += mean * mean;
                predicted[i][c] += result.aovs.pixels[3 * i + c] / (result.image.pixels[4 * i + 3] - 1) / SEEDS;
            }
        image_free(&result.image);
        image_free(&result.aovs);
    }
    double spread = 0, prediction = 0;
    for (int i = 0; i < WIDTH * HEIGHT; i++)
        for (int c = 0; c < 3; c++) {
            double mean = sum[i][c] / SEEDS;
            spread += (sum_squares[i][c] - SEEDS * mean * mean) / (SEEDS - 1);
            prediction += predicted[i][c];
        }
    print_message("spread of the seeds / predicted variance of the mean: %.3f\n", spread / prediction);
    assert_true(prediction > 0);
    assert_true(spread / prediction < 1.1);
    assert_true(spread / prediction > 0.1);
}

/* A render without the variance layers leaves the squares out of the tracer's state
 * (gpu.h GPU_OMIT_SQUARES), a variant of its own in the context's program cache: the same
 * context then renders the layers exactly as before (two_valued_samples again), and the
 * colours do not differ. */
static void squares_left_out_and_back(void **state)
{
    render_result plain;
    render_text_with(two_valued_scene, 1, false, true, &plain);
    assert_int_equal(plain.aovs.channels, 0);
    two_valued_samples(state);
    render_result with_layers;
    render_text(two_valued_scene, 1, false, &with_layers);
    assert_memory_equal(plain.image.pixels, with_layers.image.pixels, 24 * 24 * 4 * sizeof(float));
    image_free(&plain.image);
    image_free(&with_layers.image);
    image_free(&with_layers.aovs);
}

/* The memory renders are tiled by counts the squares' state only where the state keeps it:
 * with the variance layers (and their own bytes) or the whole tracer. */
static void budget_counts_the_squares_where_kept(void **state)
{
    (void)state;
    render_options plain = render_options_defaults(), variance = plain, full = plain;
    variance.variance = true;
    full.full_tracer = true;
    assert_int_equal(render_bytes_per_pixel(&full, 0) - render_bytes_per_pixel(&plain, 0),
                     GPU_TRACER_SQUARES_BYTES_PER_PIXEL);
    assert_true(render_bytes_per_pixel(&variance, 0) > render_bytes_per_pixel(&full, 0));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(squares_left_out_and_back),
        cmocka_unit_test(budget_counts_the_squares_where_kept),
        cmocka_unit_test(two_valued_samples),
        cmocka_unit_test(grey_channels_agree),
        cmocka_unit_test(predicts_the_spread_of_seeds),
    };
    return cmocka_run_group_tests(tests, gpu_fixture_set_up, gpu_fixture_tear_down);
}
