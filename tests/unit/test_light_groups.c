/* test_light_groups.c: light groups (scene.h light_groups, render_options.light_groups,
 * core/relight.h): the group clauses and their errors; on the device, that the layers sum
 * to the beauty image, that a light's layer is (statistically) the render without the
 * other light, and that relighting a group by k is the render with that light k times as
 * strong. The statistical checks are Z-tests on per-pixel differences over image
 * quadrants: pixels are independent (glsl/random.glsl), so the mean difference over N
 * pixels has the standard error sd / sqrt(N). The largest |Z| of the 12 tests (4
 * quadrants x 3 channels) at seeds 3, 4, 5 and 7 was 2.97, 1.97, 1.17, 2.03, and 1.74 at
 * 512 spp (no bias growing with the samples), 2026-12-01; seed 4 is the one used. */
#include "gpu.h"
#include "relight.h"
#include "render.h"
#include "scene_parse.h"

#include "support.h"

/* A scene of two point lights (groups key and fill) over a floor and a ball, under a
 * black sky; key_intensity and fill_intensity 0 leave that light out. */
static void two_light_scene(char *text, size_t size, double key_intensity, double fill_intensity)
{
    int used = snprintf(text, size,
                        "render size 32 24 spp 64 depth 6 seed 4\n"
                        "camera from 0 2 6 at 0 0.5 0 up 0 1 0 fov 40\n"
                        "sky constant 0 0 0\n"
                        "material floor lambertian 0.6 0.6 0.6\n"
                        "material clay lambertian 0.7 0.4 0.3\n"
                        "quad -6 0 -6  0 0 12  12 0 0  floor\n"
                        "sphere 0 0.6 0 0.6 clay\n");
    if (key_intensity > 0)
        used += snprintf(text + used, size - (size_t)used,
                         "light point -2 2.5 1.5 color 1 0.85 0.7 intensity %.17g group key\n", key_intensity);
    if (fill_intensity > 0)
        snprintf(text + used, size - (size_t)used, "light point 2 1.5 2 color 0.6 0.8 1 intensity %.17g group fill\n",
                 fill_intensity);
}

/* Renders scene text on context (with light groups when asked) into *result. */
static void render_text(gpu_context *context, const char *text, bool light_groups, render_result *result)
{
    scene s;
    rt_error error = {{0}};
    if (scene_load_string(text, "two-lights", NULL, &s, &error) != RT_OK)
        fail_msg("scene: %s", error.message);
    render_options options = render_options_defaults();
    options.light_groups = light_groups;
    if (render_scene(context, &s, &options, result, &error) != RT_OK)
        fail_msg("render: %s", error.message);
    scene_free(&s);
}

/* The largest |Z| over the image's quadrants and colour channels of the mean of
 * a[channel a_first + c] - b[channel b_first + c]. */
static double largest_z(const rt_image *a, int a_first, const rt_image *b, int b_first)
{
    double largest = 0;
    for (int quadrant = 0; quadrant < 4; quadrant++)
        for (int c = 0; c < 3; c++) {
            int x0 = quadrant % 2 * a->width / 2, y0 = quadrant / 2 * a->height / 2;
            double sum = 0, squares = 0;
            int n = 0;
            for (int y = y0; y < y0 + a->height / 2; y++)
                for (int x = x0; x < x0 + a->width / 2; x++) {
                    size_t i = (size_t)y * a->width + x;
                    double d = a->pixels[i * a->channels + a_first + c] - b->pixels[i * b->channels + b_first + c];
                    sum += d;
                    squares += d * d;
                    n++;
                }
            double mean = sum / n, variance = (squares - n * mean * mean) / (n - 1);
            double z = variance > 0 ? fabs(mean) / sqrt(variance / n) : (mean == 0 ? 0 : INFINITY);
            if (z > largest)
                largest = z;
        }
    return largest;
}

/* The index of the channel called name, or a failed test. */
static int channel_of(const rt_image *image, const char *name)
{
    for (int c = 0; c < image->channels; c++)
        if (strcmp(image->channel_names[c], name) == 0)
            return c;
    fail_msg("no channel %s", name);
    return -1;
}

static gpu_context *create_context(void)
{
    gpu_context *context = NULL;
    rt_error error = {{0}};
    if (gpu_create(NULL, &context, &error) != RT_OK)
        fail_msg("no device to render on: %s", error.message);
    return context;
}

/* group clauses: groups are numbered in the order named after "default"; the same name is
 * one group; lights, emissive materials and the sky each take one. */
static void clauses_name_groups(void **state)
{
    (void)state;
    scene s;
    rt_error error = {{0}};
    const char *text = "sky gradient 0 0 0 1 1 1 group world\n"
                       "material lamp emissive 1 1 1 strength 2 group lamps\n"
                       "material plain emissive 1 1 1\n"
                       "light point 0 1 0 group key\n"
                       "light sun 0 -1 0 group world\n"
                       "light spot 0 2 0 at 0 0 0 cone 10 20 group lamps intensity 3\n"
                       "light point 0 3 0\n";
    assert_int_equal(scene_load_string(text, "groups", NULL, &s, &error), RT_OK);
    assert_int_equal(s.light_group_count, 4);
    assert_string_equal(s.light_groups[0], "default");
    assert_string_equal(s.light_groups[1], "world");
    assert_string_equal(s.light_groups[2], "lamps");
    assert_string_equal(s.light_groups[3], "key");
    assert_int_equal(s.sky.light_group, 1);
    assert_int_equal(s.materials[0].light_group, 2);
    assert_int_equal(s.materials[1].light_group, 0);
    assert_int_equal(s.lights[0].light_group, 3);
    assert_int_equal(s.lights[1].light_group, 1);
    assert_int_equal(s.lights[2].light_group, 2);
    assert_true(s.lights[2].color[0] == 3.0f);
    assert_int_equal(s.lights[3].light_group, 0);
    scene_free(&s);
}

/* Bad group names and too many groups: file:line:column messages. */
static void clause_errors(void **state)
{
    (void)state;
    scene s;
    rt_error error = {{0}};
    assert_int_equal(scene_load_string("light point 0 1 0 group key.R\n", "bad", NULL, &s, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "bad:1:25: light group name 'key.R' has a '.', which EXR layer names keep for "
                                       "their channels (use letters, digits, '_' and '-')");
    assert_int_equal(scene_load_string("light point 0 1 0 group\n", "bad", NULL, &s, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "bad:1:24: expected a light group (of the point light) name, found end of line");
    assert_int_equal(scene_load_string("sky constant 1 1 1 group abcdefghijklmnopqrstuvwxyz\n", "bad", NULL, &s,
                                       &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "bad:1:26: light group name 'abcdefghijklmnopqrstuvwxyz' is 26 bytes long; "
                                       "the limit is 24");
    assert_int_equal(scene_load_string("material m lambertian 1 1 1 group g\n", "bad", NULL, &s, &error),
                     RT_ERROR_INPUT);
    assert_string_equal(error.message,
                        "bad:1:29: unknown lambertian material clause 'group' (expected normal_map, phong or specular)");
    char text[4096] = "";
    for (int g = 0; g < SCENE_LIGHT_GROUP_MAX; g++)
        snprintf(text + strlen(text), sizeof text - strlen(text), "light point 0 1 0 group g%d\n", g);
    assert_int_equal(scene_load_string(text, "many", NULL, &s, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "many:32:25: light group 'g31' is one more than the 32 a scene may have");
}

/* relight_parse_weight: a scale or R,G,B; anything else refused. */
static void weights_parse(void **state)
{
    (void)state;
    relight_weight weight;
    rt_error error = {{0}};
    assert_int_equal(relight_parse_weight("key=2.5", &weight, &error), RT_OK);
    assert_string_equal(weight.group, "key");
    assert_true(weight.rgb[0] == 2.5f && weight.rgb[1] == 2.5f && weight.rgb[2] == 2.5f);
    assert_int_equal(relight_parse_weight("fill=1,0.5,0", &weight, &error), RT_OK);
    assert_true(weight.rgb[0] == 1.0f && weight.rgb[1] == 0.5f && weight.rgb[2] == 0.0f);
    const char *bad[] = {"key", "=2", "key=", "key=x", "key=1,2", "key=1,2,3,4", "key=inf"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++)
        assert_int_equal(relight_parse_weight(bad[i], &weight, &error), RT_ERROR_INPUT);

    /* What the relit file's rtspheres:postprocess records of the weights. */
    relight_weight weights[2];
    assert_int_equal(relight_parse_weight("key=2.50", &weights[0], &error), RT_OK);
    assert_int_equal(relight_parse_weight("fill=1,0.5,0", &weights[1], &error), RT_OK);
    char text[128];
    relight_describe(weights, 2, text, sizeof text);
    assert_string_equal(text, "relight key=2.5 fill=1,0.5,0");
    relight_describe(weights, 0, text, sizeof text);
    assert_string_equal(text, "relight");
}

/* On the device: the layers sum to the beauty (float rounding), each light's layer is the
 * render without the other light (3 sigma per quadrant, while the beauty is far from it),
 * and relighting key by 3 is the render with key 3 times as strong. */
static void layers_are_the_lights_alone(void **state)
{
    (void)state;
    gpu_context *context = create_context();
    char text[2048];
    render_result both, key_only, fill_only, key_tripled;
    two_light_scene(text, sizeof text, 6, 3);
    render_text(context, text, true, &both);
    two_light_scene(text, sizeof text, 6, 0);
    render_text(context, text, false, &key_only);
    two_light_scene(text, sizeof text, 0, 3);
    render_text(context, text, false, &fill_only);
    two_light_scene(text, sizeof text, 18, 3);
    render_text(context, text, false, &key_tripled);
    gpu_destroy(context);

    const rt_image *groups = &both.light_groups;
    assert_int_equal(groups->channels, 9);
    assert_string_equal(groups->channel_names[0], "default.R");
    int key = channel_of(groups, "key.R"), fill = channel_of(groups, "fill.R");
    size_t pixel_count = (size_t)groups->width * groups->height;
    for (size_t i = 0; i < pixel_count; i++)
        for (int c = 0; c < 3; c++) {
            float sum = groups->pixels[i * 9 + c] + groups->pixels[i * 9 + key + c] + groups->pixels[i * 9 + fill + c];
            float beauty = both.image.pixels[4 * i + c];
            assert_close(sum, beauty, 1e-6 + 1e-5 * fabs(beauty));
            assert_true(groups->pixels[i * 9 + c] == 0.0f);   /* nothing is in default */
        }
    double z_key = largest_z(groups, key, &key_only.image, 0), z_fill = largest_z(groups, fill, &fill_only.image, 0);
    print_message("largest |Z|: key layer %.2f, fill layer %.2f; beauty against key alone %.1f\n", z_key, z_fill,
                  largest_z(&both.image, 0, &key_only.image, 0));
    assert_true(z_key < 3);
    assert_true(z_fill < 3);
    assert_true(largest_z(&both.image, 0, &key_only.image, 0) > 10);   /* the test can tell */

    /* Relight key x 3 from the layers, as `rtspheres relight --group key=3` does. */
    rt_image layered;
    rt_error error = {{0}};
    assert_int_equal(image_append_channels(&both.image, groups, &layered, &error), RT_OK);
    relight_layers layers;
    assert_int_equal(relight_find_layers(&layered, "default,key,fill", &layers, &error), RT_OK);
    relight_weight weight;
    assert_int_equal(relight_parse_weight("key=3", &weight, &error), RT_OK);
    rt_image relit;
    assert_int_equal(relight_apply(&layered, &layers, &weight, 1, &relit, &error), RT_OK);
    double z_relit = largest_z(&relit, 0, &key_tripled.image, 0);
    print_message("largest |Z|: relit key x 3 against key intensity x 3: %.2f; unrelit %.1f\n", z_relit,
                  largest_z(&both.image, 0, &key_tripled.image, 0));
    assert_true(z_relit < 3);
    assert_true(largest_z(&both.image, 0, &key_tripled.image, 0) > 10);
    /* Every weight 1 is the beauty again. */
    rt_image same;
    assert_int_equal(relight_apply(&layered, &layers, NULL, 0, &same, &error), RT_OK);
    for (size_t i = 0; i < pixel_count; i++)
        for (int c = 0; c < 3; c++)
            assert_close(same.pixels[i * same.channels + c], both.image.pixels[4 * i + c],
                         1e-6 + 1e-5 * fabs(both.image.pixels[4 * i + c]));
    assert_string_equal(same.channel_names[3], "samples");
    weight.group[0] = 'x';
    assert_int_equal(relight_apply(&layered, &layers, &weight, 1, &relit, &error), RT_ERROR_INPUT);
    assert_string_equal(error.message, "RELIGHT: no light group 'xey' in the image; it has default,key,fill");
    image_free(&same);
    image_free(&relit);
    image_free(&layered);
    render_result *results[] = {&both, &key_only, &fill_only, &key_tripled};
    for (int r = 0; r < 4; r++) {
        image_free(&results[r]->image);
        image_free(&results[r]->light_groups);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(clauses_name_groups),
        cmocka_unit_test(clause_errors),
        cmocka_unit_test(weights_parse),
        cmocka_unit_test(layers_are_the_lights_alone),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
