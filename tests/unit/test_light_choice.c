/* test_light_choice.c: the choice of a light for next-event estimation (glsl/lights.glsl,
 * choose_light_at and light_choice_probability) on the device that renders (gpu.h
 * gpu_light_choice_test), for a scene of 6 lights (chosen by the point) and one of 40 (the
 * light tree), at points on surfaces of every orientation and in media:
 *   - the chance MIS finds again from the memo a choice leaves is the chance the choice
 *     reported, for every light it picks (else light and BSDF sampling weigh one path
 *     differently and the image is biased);
 *   - the chances of all lights at a point add up to 1;
 *   - the lights picked follow those chances: from stratified u each light is picked as
 *     often as its chance says to within 2 (the walk splits [0, 1) into one interval a
 *     light), and from independent u by a chi-square test (as Mitsuba tests its sampling
 *     routines against their densities); no light of chance 0 is ever picked.
 * Every kind of light is there: points, spots aimed every way, quads, triangles and
 * spheres facing every way, a sun. */
#include "gpu.h"
#include "pack.h"
#include "scene.h"
#include "scene_parse.h"

#include "support.h"

static gpu_context *context;

/* The two scenes, packed. */
static packed_scene few, many;

enum { FEW_LIGHTS = 6, MANY_LIGHTS = 40 };

/* Appends one light of kind k (0 to 5) at a random place in [-4, 4]^3 to text. */
static void append_light(char *text, size_t size, int k, random_source *source)
{
    float x = random_float(source, -4, 4), y = random_float(source, -4, 4), z = random_float(source, -4, 4);
    float a = random_float(source, -1, 1), b = random_float(source, -1, 1), c = random_float(source, -1, 1);
    float d = random_float(source, -1, 1), e = random_float(source, -1, 1), f = random_float(source, -1, 1);
    char line[256];
    switch (k % 6) {
    case 0:
        snprintf(line, sizeof line, "light point %g %g %g intensity %g\n", x, y, z, random_float(source, 1, 5));
        break;
    case 1:
        snprintf(line, sizeof line, "light spot %g %g %g at %g %g %g intensity %g cone %g %g\n", x, y, z, x + a, y + b,
                 z + c, random_float(source, 1, 5), 10.0f, random_float(source, 15, 80));
        break;
    case 2:
        snprintf(line, sizeof line, "quad %g %g %g  %g %g %g  %g %g %g glow\n", x, y, z, a, b, c, d, e, f);
        break;
    case 3:
        snprintf(line, sizeof line, "triangle %g %g %g  %g %g %g  %g %g %g glow\n", x, y, z, x + a, y + b, z + c,
                 x + d, y + e, z + f);
        break;
    case 4:
        snprintf(line, sizeof line, "sphere %g %g %g %g glow\n", x, y, z, random_float(source, 0.1f, 0.8f));
        break;
    default:
        snprintf(line, sizeof line, "light sun %g %g %g intensity 0.5 angle 2\n", a, b - 1.5f, c);
        break;
    }
    strncat(text, line, size - strlen(text) - 1);
}

/* Packs a scene of count random lights (one sun at most) into *out. */
static int pack_lights_scene(int count, uint64_t seed, packed_scene *out)
{
    char text[16384] = "material glow emissive 1 0.8 0.6 strength 4\n";
    random_source source = {seed};
    for (int k = 0; k < count; k++)
        append_light(text, sizeof text, k == count - 1 ? 5 : k % 5, &source);
    scene s;
    rt_error error;
    if (scene_load_string(text, "lights", NULL, &s, &error) != RT_OK) {
        print_error("%s\n", error.message);
        return -1;
    }
    rt_status status = pack_scene(&s, NULL, out, &error);
    scene_free(&s);
    if (status != RT_OK) {
        print_error("%s\n", error.message);
        return -1;
    }
    return 0;
}

static int set_up(void **state)
{
    (void)state;
    rt_error error;
    if (gpu_create(NULL, &context, &error) != RT_OK) {
        print_error("%s\n", error.message);
        return -1;
    }
    if (pack_lights_scene(FEW_LIGHTS, 11, &few) != 0 || pack_lights_scene(MANY_LIGHTS, 12, &many) != 0)
        return -1;
    return 0;
}

static int tear_down(void **state)
{
    (void)state;
    packed_scene_free(&few);
    packed_scene_free(&many);
    gpu_destroy(context);
    return 0;
}

/* Runs count queries against a packed scene; the caller frees the results. */
static gpu_light_result *run(const packed_scene *packed, const gpu_light_query *queries, int count)
{
    gpu_light_result *results = calloc((size_t)count, sizeof *results);
    assert_non_null(results);
    rt_error error;
    if (gpu_light_choice_test(context, packed->texels, packed->texel_count, queries, count, results, &error) != RT_OK)
        fail_msg("%s", error.message);
    return results;
}

/* A random point in [-5, 5]^3 and, one time in four, no normal (a point in a medium),
 * else a random unit normal. */
static gpu_light_query random_query(random_source *source)
{
    gpu_light_query q = {.u = random_float(source, 0, 1)};
    for (int k = 0; k < 3; k++)
        q.p[k] = random_float(source, -5, 5);
    if (random_below(source, 4) != 0) {
        double z = random_float(source, -1, 1), phi = random_float(source, 0, (float)(2 * M_PI));
        double r = sqrt(fmax(0, 1 - z * z));
        q.n[0] = (float)(r * cos(phi)), q.n[1] = (float)(r * sin(phi)), q.n[2] = (float)z;
    }
    return q;
}

/* Every light picked has the chance the choice reported, found again from its memo; the
 * lights' chances at a point add up to 1. */
static void check_chances(const packed_scene *packed, uint32_t light_count, uint64_t seed)
{
    assert_int_equal(packed->light_count, light_count);
    enum { POINTS = 64 };
    random_source source = {seed};
    gpu_light_query *queries = malloc((size_t)POINTS * light_count * sizeof *queries);
    assert_non_null(queries);
    for (int point = 0; point < POINTS; point++) {
        gpu_light_query at = random_query(&source);
        for (uint32_t l = 0; l < light_count; l++) {
            queries[point * light_count + l] = at;
            queries[point * light_count + l].light = l;
            queries[point * light_count + l].u = random_float(&source, 0, 1);
        }
    }
    gpu_light_result *r = run(packed, queries, POINTS * (int)light_count);
    for (int point = 0; point < POINTS; point++) {
        double sum = 0;
        for (uint32_t l = 0; l < light_count; l++) {
            const gpu_light_result *result = &r[point * light_count + l];
            assert_true(result->picked < light_count);
            assert_true(result->chance > 0);
            if (result->picked_again != result->chance)
                fail_msg("point %d: light %u picked with chance %.9g, found again as %.9g", point, result->picked,
                         (double)result->chance, (double)result->picked_again);
            assert_true(result->light_chance >= 0);
            sum += result->light_chance;
        }
        if (fabs(sum - 1) > 1e-5)
            fail_msg("point %d: the lights' chances add up to %.9g", point, sum);
    }
    free(r);
    free(queries);
}

static void chances_are_found_again_and_add_up_chosen_by_the_point(void **state)
{
    (void)state;
    assert_true(few.light_tree_offset == PACKED_NONE);
    check_chances(&few, FEW_LIGHTS, 21);
}

static void chances_are_found_again_and_add_up_in_the_tree(void **state)
{
    (void)state;
    assert_true(many.light_tree_offset != PACKED_NONE);
    check_chances(&many, MANY_LIGHTS, 22);
}

/* At a few points, COUNT choices from stratified u (one in each [i, i + 1) / COUNT): each
 * light picked COUNT x its chance times to within 2; then COUNT choices from independent u
 * against the same expected counts by a chi-square test (cells expected below 5 pooled),
 * significance 0.01 over all the points (Sidak). A light of chance 0 is never picked. */
static void check_choices_follow_chances(const packed_scene *packed, uint32_t light_count, uint64_t seed)
{
    enum { POINTS = 6, COUNT = 1 << 16 };
    const double significance = 1 - pow(1 - 0.01, 1.0 / POINTS);
    random_source source = {seed};
    gpu_light_query *queries = malloc((size_t)COUNT * sizeof *queries);
    assert_non_null(queries);
    double *expected = calloc(light_count, sizeof *expected), *observed = calloc(light_count, sizeof *observed);
    assert_true(expected != NULL && observed != NULL);
    for (int point = 0; point < POINTS; point++) {
        gpu_light_query at = random_query(&source);
        for (int i = 0; i < COUNT; i++) {
            queries[i] = at;
            queries[i].u = (float)((i + random_float(&source, 0, 1)) / COUNT);
            queries[i].light = (uint32_t)i % light_count;
        }
        gpu_light_result *r = run(packed, queries, COUNT);
        for (uint32_t l = 0; l < light_count; l++) {
            expected[l] = (double)r[l].light_chance * COUNT;
            observed[l] = 0;
        }
        for (int i = 0; i < COUNT; i++) {
            assert_true(r[i].picked < light_count);
            observed[r[i].picked]++;
        }
        for (uint32_t l = 0; l < light_count; l++)
            if (fabs(observed[l] - expected[l]) > 2 || (expected[l] == 0 && observed[l] > 0))
                fail_msg("point %d, stratified: light %u picked %.0f times, its chance says %.2f", point, l,
                         observed[l], expected[l]);
        free(r);
        for (int i = 0; i < COUNT; i++)
            queries[i].u = random_float(&source, 0, 1);
        r = run(packed, queries, COUNT);
        for (uint32_t l = 0; l < light_count; l++)
            observed[l] = 0;
        for (int i = 0; i < COUNT; i++) {
            assert_true(r[i].picked < light_count);
            observed[r[i].picked]++;
        }
        double chi2 = 0, pooled_observed = 0, pooled_expected = 0;
        int cells = 0;
        for (uint32_t l = 0; l < light_count; l++) {
            if (expected[l] == 0 && observed[l] > 0)
                fail_msg("point %d: light %u has chance 0 but was picked %.0f times", point, l, observed[l]);
            if (expected[l] < 5) {
                pooled_observed += observed[l], pooled_expected += expected[l];
                continue;
            }
            chi2 += (observed[l] - expected[l]) * (observed[l] - expected[l]) / expected[l];
            cells++;
        }
        if (pooled_expected > 0) {
            chi2 += (pooled_observed - pooled_expected) * (pooled_observed - pooled_expected) / pooled_expected;
            cells++;
        }
        double p_value = cells > 1 ? 1 - lower_gamma_regularised((cells - 1) / 2.0, chi2 / 2) : 1;
        print_message("point %d: chi2 %.1f over %d cells, p %.3g\n", point, chi2, cells, p_value);
        if (!(p_value >= significance))
            fail_msg("point %d: the lights picked do not follow their chances (p-value %g < %g)", point, p_value,
                     significance);
        free(r);
    }
    free(expected);
    free(observed);
    free(queries);
}

static void choices_follow_their_chances_chosen_by_the_point(void **state)
{
    (void)state;
    check_choices_follow_chances(&few, FEW_LIGHTS, 31);
}

static void choices_follow_their_chances_in_the_tree(void **state)
{
    (void)state;
    check_choices_follow_chances(&many, MANY_LIGHTS, 32);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(chances_are_found_again_and_add_up_chosen_by_the_point),
        cmocka_unit_test(chances_are_found_again_and_add_up_in_the_tree),
        cmocka_unit_test(choices_follow_their_chances_chosen_by_the_point),
        cmocka_unit_test(choices_follow_their_chances_in_the_tree),
    };
    return cmocka_run_group_tests(tests, set_up, tear_down);
}
