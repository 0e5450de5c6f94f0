/* test_material_pbr.c: the pbr material (glsl/material_pbr.glsl) on the device that renders
 * (gpu.h gpu_material_test): its sampling against its density by a chi-square test as
 * Mitsuba's BSDF tests do it, the density MIS is given against the sampled one, weights
 * against evaluate / pdf, white furnaces against single-scattering GGX integrated here in
 * double precision, reciprocity, the roughness-0 limit against the metal and dielectric
 * materials, and vertex colours in a render. */
#include "gpu.h"
#include "pack.h"
#include "render.h"
#include "scene.h"

#include "support.h"

static gpu_context *context;
static packed_scene packed;

/* The scene's materials, by index. */
enum {
    METAL_03, METAL_06, METAL_10, DIELECTRIC_05, MIXED_04, GLASS_05, HALF_GLASS_07, /* rough */
    METAL_WHITE_01, METAL_WHITE_04, METAL_WHITE_07, METAL_WHITE_10,                    /* furnaces */
    GLASS_WHITE_01, GLASS_WHITE_04, GLASS_WHITE_07, GLASS_WHITE_10,
    SMOOTH_METAL, SMOOTH_GLASS, FUZZLESS_METAL, DIELECTRIC_15,                         /* the limit */
    FUZZY_METAL,                                                                       /* fuzz 1 */
    MATERIAL_COUNT
};

/* ---- vectors in double ------------------------------------------------------------ */

typedef struct vec {
    double x, y, z;
} vec;

static vec make_vec(double x, double y, double z) { return (vec){x, y, z}; }
static vec add(vec a, vec b) { return make_vec(a.x + b.x, a.y + b.y, a.z + b.z); }
static vec scale(vec a, double s) { return make_vec(a.x * s, a.y * s, a.z * s); }
static double dot(vec a, vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static vec normalized(vec a) { return scale(a, 1 / sqrt(dot(a, a))); }
static vec cross(vec a, vec b) { return make_vec(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x); }

/* A frame (tangent, bitangent, normal) around a unit normal. */
typedef struct frame {
    vec t, b, n;
} frame;

static frame frame_around(vec n)
{
    vec helper = fabs(n.x) < 0.9 ? make_vec(1, 0, 0) : make_vec(0, 1, 0);
    vec t = normalized(cross(helper, n));
    return (frame){t, cross(n, t), n};
}

static vec to_world(const frame *f, vec local)
{
    return add(add(scale(f->t, local.x), scale(f->b, local.y)), scale(f->n, local.z));
}

static vec to_local(const frame *f, vec w) { return make_vec(dot(w, f->t), dot(w, f->b), dot(w, f->n)); }

static void store(float out[3], vec v)
{
    out[0] = (float)v.x, out[1] = (float)v.y, out[2] = (float)v.z;
}

static vec load(const float v[3]) { return make_vec(v[0], v[1], v[2]); }

/* A uniform number in [0, 1) with 24 bits, as the tracer's (glsl/random.glsl). */
static float uniform(uint64_t *state) { return (float)(splitmix64_next(state) >> 40) / 16777216.0f; }

/* ---- the scene and the device ------------------------------------------------------ */

static void add_pbr(scene *s, const char *name, float base, float metallic, float roughness, float transmission)
{
    scene_material m = scene_material_defaults();
    snprintf(m.name, sizeof m.name, "%s", name);
    m.type = MATERIAL_PBR;
    m.albedo[0] = m.albedo[1] = m.albedo[2] = base;
    if (base < 1)
        m.albedo[1] *= 0.7f, m.albedo[2] *= 0.4f;      /* a colour: the lobe choice uses the mean */
    m.metallic = metallic;
    m.roughness = roughness;
    m.transmission = transmission;
    m.index_of_refraction = 1.5f;
    assert_true(scene_add_material(s, &m) >= 0);
}

static int set_up(void **state)
{
    (void)state;
    rt_error error;
    if (gpu_create(NULL, &context, &error) != RT_OK) {
        print_error("%s\n", error.message);
        return -1;
    }
    scene s;
    scene_defaults(&s);
    add_pbr(&s, "metal-0.3", 0.9f, 1, 0.3f, 0);
    add_pbr(&s, "metal-0.6", 0.9f, 1, 0.6f, 0);
    add_pbr(&s, "metal-1", 0.9f, 1, 1, 0);
    add_pbr(&s, "dielectric-0.5", 0.8f, 0, 0.5f, 0);
    add_pbr(&s, "mixed-0.4", 0.8f, 0.5f, 0.4f, 0);
    add_pbr(&s, "glass-0.5", 1, 0, 0.5f, 1);
    add_pbr(&s, "half-glass-0.7", 0.8f, 0.2f, 0.7f, 0.5f);
    const float roughnesses[4] = {0.1f, 0.4f, 0.7f, 1};
    for (int i = 0; i < 4; i++)
        add_pbr(&s, "metal-white", 1, 1, roughnesses[i], 0);
    for (int i = 0; i < 4; i++)
        add_pbr(&s, "glass-white", 1, 0, roughnesses[i], 1);
    add_pbr(&s, "smooth-metal", 1, 1, 0, 0);
    add_pbr(&s, "smooth-glass", 1, 0, 0, 1);
    scene_material metal = scene_material_defaults(), glass = scene_material_defaults();
    metal.type = MATERIAL_METAL;
    metal.albedo[0] = metal.albedo[1] = metal.albedo[2] = 1;
    glass.type = MATERIAL_DIELECTRIC;
    glass.index_of_refraction = 1.5f;
    assert_true(scene_add_material(&s, &metal) == FUZZLESS_METAL);
    assert_true(scene_add_material(&s, &glass) == DIELECTRIC_15);
    metal.fuzz = 1;
    assert_true(scene_add_material(&s, &metal) == FUZZY_METAL);
    rt_status status = pack_scene(&s, NULL, &packed, &error);
    scene_free(&s);
    return status == RT_OK ? 0 : -1;
}

static int tear_down(void **state)
{
    (void)state;
    packed_scene_free(&packed);
    gpu_destroy(context);
    return 0;
}

/* A query of material at a surface of normal n (also its shading normal and the light's
 * direction), seen from view (unit, on the side front_face says), with no numbers drawn. */
static gpu_material_query query_from(uint32_t material, vec view, vec n, bool front_face)
{
    gpu_material_query q = {.front_face = front_face, .material = material};
    store(q.direction, scale(view, -1));
    store(q.normal, n);
    store(q.shading, n);
    store(q.to_light, n);
    return q;
}

/* Runs count queries on the device; the caller frees the results. */
static gpu_material_result *run(const gpu_material_query *queries, int count)
{
    gpu_material_result *results = calloc((size_t)count, sizeof *results);
    assert_non_null(results);
    rt_error error;
    rt_status status = gpu_material_test(context, packed.texels, packed.texel_count, queries, count, results, &error);
    if (status != RT_OK)
        fail_msg("%s", error.message);
    return results;
}

/* A view seen from a surface whose (geometric = shading) normal is the frame's: the ray
 * arrives along -view; inside: from the far side (the frame then faces the ray there). */
typedef struct setup {
    int material;
    double view_degrees;         /* angle of the view to the normal */
    bool inside;                 /* the ray comes from inside the body (front_face false) */
} setup;

static const vec tilted_normal = {0.2, 0.9, 0.3};

/* The query for s with uniform numbers u and to_light l (world), in frame f. */
static gpu_material_query make_query(const setup *s, const frame *f, const float u[4], vec l)
{
    double angle = s->view_degrees * M_PI / 180;
    vec view = to_world(f, make_vec(sin(angle), 0, cos(angle)));
    gpu_material_query q = {.front_face = !s->inside, .material = (uint32_t)s->material};
    store(q.direction, scale(view, -1));
    store(q.normal, f->n);
    store(q.shading, f->n);
    memcpy(q.u, u, sizeof q.u);
    store(q.to_light, l);
    return q;
}

/* count samples of s (uniform numbers from seed); the caller frees them. */
static gpu_material_result *draw_samples(const setup *s, const frame *f, int count, uint64_t seed)
{
    gpu_material_query *queries = malloc((size_t)count * sizeof *queries);
    assert_non_null(queries);
    for (int i = 0; i < count; i++) {
        float u[4] = {uniform(&seed), uniform(&seed), uniform(&seed), uniform(&seed)};
        queries[i] = make_query(s, f, u, f->n);
    }
    gpu_material_result *results = run(queries, count);
    free(queries);
    return results;
}

/* ---- the chi-square test ------------------------------------------------------------ */

/* The grid of the test: cos theta (to the frame's normal) from -1 to 1, phi 0 to 2 pi. */
enum { THETA_CELLS = 40, PHI_CELLS = 80, QUADRATURE = 4, CHI2_SAMPLES = 1 << 20 };
#define POOL_BELOW 5.0
/* Mitsuba's significance level, split over the tests by Sidak's correction. */
#define SIGNIFICANCE 0.01
#define CHI2_TESTS 8

/* The expected count of each cell: samples x the integral of the material's pdf over the
 * cell (in d(cos theta) d(phi)), by Gauss-Legendre quadrature of QUADRATURE points a side:
 * points inside the cell, since the density jumps at the horizon, a cell boundary. */
static void expected_counts(const setup *s, const frame *f, double samples, double *expected)
{
    enum { POINTS = QUADRATURE * QUADRATURE };
    static const double nodes[QUADRATURE] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                             0.8611363115940526};
    static const double weights[QUADRATURE] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                               0.3478548451374538};
    size_t count = (size_t)THETA_CELLS * PHI_CELLS * POINTS;
    gpu_material_query *queries = malloc(count * sizeof *queries);
    assert_non_null(queries);
    const float u[4] = {0.5f, 0.5f, 0.5f, 0.5f};
    const double height = 2.0 / THETA_CELLS, width = 2 * M_PI / PHI_CELLS;
    for (int cell = 0; cell < THETA_CELLS * PHI_CELLS; cell++)
        for (int k = 0; k < POINTS; k++) {
            double cos_theta = -1 + height * (cell / PHI_CELLS + 0.5 + 0.5 * nodes[k / QUADRATURE]);
            double phi = width * (cell % PHI_CELLS + 0.5 + 0.5 * nodes[k % QUADRATURE]);
            double sin_theta = sqrt(fmax(0, 1 - cos_theta * cos_theta));
            vec l = to_world(f, make_vec(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta));
            queries[(size_t)cell * POINTS + k] = make_query(s, f, u, l);
        }
    gpu_material_result *results = run(queries, (int)count);
    for (int cell = 0; cell < THETA_CELLS * PHI_CELLS; cell++) {
        double sum = 0;
        for (int k = 0; k < POINTS; k++)
            sum += weights[k / QUADRATURE] * weights[k % QUADRATURE] * results[(size_t)cell * POINTS + k].evaluate_pdf;
        expected[cell] = samples * height * width * sum / 4;
    }
    free(results);
    free(queries);
}

/* The chi-square test of s: samples binned into the grid against the expected counts,
 * cells expected below POOL_BELOW pooled into one; fails when the p-value is below the
 * corrected significance, when the samples fall where the density is 0, or when the
 * density's integral is not the share of samples that are not absorbed. */
static void chi_square_test(const setup *s, uint64_t seed)
{
    frame f = frame_around(normalized(tilted_normal));
    gpu_material_result *samples = draw_samples(s, &f, CHI2_SAMPLES, seed);
    static double observed[THETA_CELLS * PHI_CELLS], expected[THETA_CELLS * PHI_CELLS];
    memset(observed, 0, sizeof observed);
    double kept = 0;
    for (int i = 0; i < CHI2_SAMPLES; i++) {
        if (samples[i].absorbed)
            continue;
        vec d = to_local(&f, load(samples[i].direction));
        double phi = atan2(d.y, d.x);
        phi = phi < 0 ? phi + 2 * M_PI : phi;
        int row = (int)((d.z + 1) / 2 * THETA_CELLS), column = (int)(phi / (2 * M_PI) * PHI_CELLS);
        row = row < 0 ? 0 : row >= THETA_CELLS ? THETA_CELLS - 1 : row;
        column = column < 0 ? 0 : column >= PHI_CELLS ? PHI_CELLS - 1 : column;
        observed[row * PHI_CELLS + column]++;
        kept++;
    }
    free(samples);
    expected_counts(s, &f, CHI2_SAMPLES, expected);
    double chi2 = 0, pooled_observed = 0, pooled_expected = 0, total_expected = 0;
    int cells = 0;
    for (int k = 0; k < THETA_CELLS * PHI_CELLS; k++) {
        total_expected += expected[k];
        if (expected[k] < 1e-9 * CHI2_SAMPLES && observed[k] > 0)
            fail_msg("material %d: %.0f samples in cell %d, where the density is 0", s->material, observed[k], k);
        if (expected[k] < POOL_BELOW) {
            pooled_observed += observed[k];
            pooled_expected += expected[k];
            continue;
        }
        chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
        cells++;
    }
    if (pooled_expected >= POOL_BELOW) {
        chi2 += (pooled_observed - pooled_expected) * (pooled_observed - pooled_expected) / pooled_expected;
        cells++;
    }
    double p_value = 1 - lower_gamma_regularised((cells - 1) / 2.0, chi2 / 2);
    double significance = 1 - pow(1 - SIGNIFICANCE, 1.0 / CHI2_TESTS);
    print_message("material %d, view %g degrees%s: %.0f of %d kept, density integral %.1f, chi2 %.1f over %d cells, "
                  "p %.3g\n", s->material, s->view_degrees, s->inside ? " from inside" : "", kept, CHI2_SAMPLES,
                  total_expected, chi2, cells, p_value);
    /* The density integrates to the share kept (the quadrature's error, the samples' noise). */
    assert_true(fabs(total_expected - kept) < 0.005 * CHI2_SAMPLES + 5 * sqrt(kept));
    if (!(p_value >= significance)) {
        /* The cells that disagree most, to tell a wrong density from a wrong sampler. */
        for (int shown = 0; shown < 8; shown++) {
            int worst = -1;
            double worst_term = 0;
            for (int k = 0; k < THETA_CELLS * PHI_CELLS; k++) {
                double term = expected[k] >= POOL_BELOW ? (observed[k] - expected[k]) * (observed[k] - expected[k])
                                                          / expected[k] : 0;
                if (term > worst_term)
                    worst_term = term, worst = k;
            }
            if (worst < 0)
                break;
            print_message("  cell cos theta row %d, phi column %d: observed %.0f, expected %.1f\n",
                          worst / PHI_CELLS, worst % PHI_CELLS, observed[worst], expected[worst]);
            expected[worst] = 0;
        }
        fail_msg("material %d: the samples do not follow the density (p-value %g < %g)", s->material, p_value,
                 significance);
    }
}

static void metal_sampling_follows_its_density(void **state)
{
    (void)state;
    const setup setups[] = {{METAL_03, 30, false}, {METAL_06, 70, false}, {METAL_10, 10, false}};
    for (int i = 0; i < 3; i++)
        chi_square_test(&setups[i], 100 + (uint64_t)i);
}

static void dielectric_sampling_follows_its_density(void **state)
{
    (void)state;
    const setup setups[] = {{DIELECTRIC_05, 45, false}, {MIXED_04, 60, false}};
    for (int i = 0; i < 2; i++)
        chi_square_test(&setups[i], 200 + (uint64_t)i);
}

static void transmission_sampling_follows_its_density(void **state)
{
    (void)state;
    const setup setups[] = {{GLASS_05, 40, false}, {GLASS_05, 40, true}, {HALF_GLASS_07, 75, false}};
    for (int i = 0; i < 3; i++)
        chi_square_test(&setups[i], 300 + (uint64_t)i);
}

/* ---- what MIS is given, and the weights ---------------------------------------------- */

/* For every sample of the rough setups: the pdf it carries is the material's pdf at its
 * direction (0 for a transmitted one: light sampling gathers only above the surface), and
 * its weight is evaluate / pdf there. */
static void samples_carry_their_density_and_weight(void **state)
{
    (void)state;
    const setup setups[] = {{METAL_06, 50, false}, {MIXED_04, 20, false}, {GLASS_05, 60, false},
                            {GLASS_05, 30, true}, {HALF_GLASS_07, 80, false}};
    frame f = frame_around(normalized(tilted_normal));
    for (int k = 0; k < 5; k++) {
        enum { COUNT = 1 << 16 };
        gpu_material_result *r = draw_samples(&setups[k], &f, COUNT, 400 + (uint64_t)k);
        int kept = 0, transmitted = 0;
        for (int i = 0; i < COUNT; i++) {
            if (r[i].absorbed)
                continue;
            kept++;
            assert_true(r[i].light_sampled);
            assert_true(r[i].sampled_pdf > 0);
            bool below = dot(load(r[i].direction), f.n) < 0;
            transmitted += below;
            if (below)
                assert_true(r[i].pdf == 0);
            else
                assert_relative(r[i].pdf, r[i].sampled_pdf, 1e-5);
            for (int c = 0; c < 3; c++)
                assert_relative(r[i].weight[c], r[i].sampled_evaluate[c] / r[i].sampled_pdf, 1e-4);
        }
        assert_true(kept > COUNT / 2);
        if (setups[k].material == GLASS_05)
            assert_true(transmitted > COUNT / 4);
        free(r);
    }
}

/* Where v.h rounds above 1 (light straight back along the view, views at the normal)
 * every value is a number: Schlick's (1 - v.h)^5 of a negative base is undefined in GLSL
 * (a chart render once had two NaN pixels from it). */
static void values_at_the_mirror_direction_are_numbers(void **state)
{
    (void)state;
    enum { COUNT = 1 << 14 };
    gpu_material_query *queries = malloc(COUNT * sizeof *queries);
    assert_non_null(queries);
    const int materials[] = {METAL_03, METAL_10, DIELECTRIC_05, MIXED_04, GLASS_05, HALF_GLASS_07};
    uint64_t seed = 800;
    for (int i = 0; i < COUNT; i++) {
        vec n = normalized(make_vec(uniform(&seed) - 0.5, uniform(&seed) - 0.5, uniform(&seed) - 0.5));
        frame f = frame_around(n);
        /* Views at or within a few float steps of the normal; the light straight back. */
        vec view = i % 2 ? n : normalized(to_world(&f, make_vec(1e-4 * (uniform(&seed) - 0.5), 0, 1)));
        queries[i] = (gpu_material_query){.front_face = i % 4 < 2, .material = (uint32_t)materials[i % 6]};
        store(queries[i].direction, scale(view, -1));
        store(queries[i].normal, n);
        store(queries[i].shading, n);
        store(queries[i].to_light, view);
        for (int k = 0; k < 4; k++)
            queries[i].u[k] = uniform(&seed);
    }
    gpu_material_result *r = run(queries, COUNT);
    for (int i = 0; i < COUNT; i++) {
        assert_true(isfinite(r[i].pdf) && isfinite(r[i].evaluate_pdf) && isfinite(r[i].sampled_pdf));
        for (int c = 0; c < 3; c++)
            if (!(isfinite(r[i].weight[c]) && isfinite(r[i].evaluate[c]) && isfinite(r[i].sampled_evaluate[c])
                  && isfinite(r[i].direction[c])))
                fail_msg("query %d (material %u, front %d): weight %g, evaluate %g, at the sample %g, direction %g",
                         i, queries[i].material, queries[i].front_face, r[i].weight[c], r[i].evaluate[c],
                         r[i].sampled_evaluate[c], r[i].direction[c]);
    }
    free(r);
    free(queries);
}

/* ---- white furnaces ------------------------------------------------------------------ */

static double lambda(vec w, double alpha)
{
    return 0.5 * (sqrt(1 + alpha * alpha * (w.x * w.x + w.y * w.y) / (w.z * w.z)) - 1);
}

/* The dielectric's Fresnel term (Schlick's on the incident cosine; 1 under total internal
 * reflection), eta_ratio = the incident side's index over the other's. */
static double fresnel(double cosine, double eta_ratio)
{
    if (eta_ratio * sqrt(fmax(0, 1 - cosine * cosine)) > 1)
        return 1;
    double r0 = (1 - eta_ratio) / (1 + eta_ratio);
    r0 *= r0;
    return r0 + (1 - r0) * pow(1 - cosine, 5);
}

/* The single-scattering albedo of GGX with height-correlated Smith masking-shadowing,
 * white base colour, for a view at cosine mu: a metal (every facet reflects all), or a
 * rough dielectric interface of index ratio eta_ratio (reflection and transmission by the
 * Fresnel term). The integral of f cos over directions is, over microfacet normals h,
 * the integral of F G2 (v.h) / mu D(h) dh, refracted directions alike (their Jacobian
 * cancels Walter's denominator); h is drawn as tan^2 theta = alpha^2 t / (1 - t) with phi
 * uniform, whose density is D cos theta_h, and the grid of (t, phi) midpoints sums it. */
static double ggx_albedo(double mu, double alpha, bool metal, double eta_ratio)
{
    enum { T_STEPS = 2048, PHI_STEPS = 512 };
    vec v = make_vec(sqrt(1 - mu * mu), 0, mu);
    double sum = 0;
    for (int i = 0; i < T_STEPS; i++) {
        double t = (i + 0.5) / T_STEPS;
        double cos_h = 1 / sqrt(1 + alpha * alpha * t / (1 - t)), sin_h = sqrt(1 - cos_h * cos_h);
        for (int j = 0; j < PHI_STEPS; j++) {
            double phi = 2 * M_PI * (j + 0.5) / PHI_STEPS;
            vec h = make_vec(sin_h * cos(phi), sin_h * sin(phi), cos_h);
            double vh = dot(v, h);
            if (vh <= 0)
                continue;
            double measure = vh / (mu * cos_h);
            double reflectance = metal ? 1 : fresnel(vh, eta_ratio);
            vec reflected = add(scale(h, 2 * vh), scale(v, -1));
            if (reflected.z > 0)
                sum += reflectance * measure / (1 + lambda(v, alpha) + lambda(reflected, alpha));
            if (reflectance < 1) {
                /* Refraction of -v through h (Snell's law in vector form). */
                double k = 1 - eta_ratio * eta_ratio * (1 - vh * vh);
                vec refracted = add(scale(v, -eta_ratio), scale(h, eta_ratio * vh - sqrt(k)));
                if (refracted.z < 0)
                    sum += (1 - reflectance) * measure / (1 + lambda(v, alpha) + lambda(refracted, alpha));
            }
        }
    }
    return sum / ((double)T_STEPS * PHI_STEPS);
}

/* The mean weight of count samples (what a white furnace renders), its standard error. */
static double mean_weight(const setup *s, int count, uint64_t seed, double *error)
{
    frame f = frame_around(make_vec(0, 0, 1));
    gpu_material_result *r = draw_samples(s, &f, count, seed);
    double sum = 0, squares = 0;
    for (int i = 0; i < count; i++) {
        double w = r[i].absorbed ? 0 : (r[i].weight[0] + r[i].weight[1] + r[i].weight[2]) / 3;
        sum += w;
        squares += w * w;
    }
    free(r);
    double mean = sum / count;
    *error = sqrt(fmax(0, squares / count - mean * mean) / count);
    return mean;
}

/* White furnaces of every roughness and several views: the energy is at most 1, and it is
 * the single-scattering albedo (what GGX without multiple scattering loses, it loses)
 * within 4 standard errors plus 0.2% for the quadrature and float rounding. */
static void furnace(int first_material, bool metal, bool inside)
{
    const double roughnesses[4] = {0.1, 0.4, 0.7, 1}, views[4] = {0, 40, 70, 85};
    for (int m = 0; m < 4; m++)
        for (int k = 0; k < 4; k++) {
            setup s = {first_material + m, views[k], inside};
            double error, energy = mean_weight(&s, 1 << 18, 500 + (uint64_t)(4 * m + k), &error);
            double mu = cos(views[k] * M_PI / 180), alpha = roughnesses[m] * roughnesses[m];
            double reference = ggx_albedo(mu, alpha, metal, inside ? 1.5 : 1 / 1.5);
            print_message("%s roughness %.1f view %2.0f%s: energy %.4f +- %.4f, single-scattering GGX %.4f (loss "
                          "%.4f)\n", metal ? "metal" : "glass", roughnesses[m], views[k], inside ? " inside" : "",
                          energy, error, reference, 1 - reference);
            assert_true(energy <= 1 + 4 * error);
            assert_true(reference <= 1 + 1e-9);
            assert_close(energy, reference, 4 * error + 0.002);
        }
}

static void metal_furnace_loses_what_single_scattering_loses(void **state)
{
    (void)state;
    furnace(METAL_WHITE_01, true, false);
}

static void rough_glass_furnace_loses_what_single_scattering_loses(void **state)
{
    (void)state;
    furnace(GLASS_WHITE_01, false, false);
    furnace(GLASS_WHITE_01, false, true);
}

/* ---- reciprocity ------------------------------------------------------------------- */

/* f(v, l) = f(l, v) for reflection: evaluate returns f cos(l), so evaluate(v, l) / cos(l)
 * against evaluate(l, v) / cos(v), for random pairs above the surface of every rough
 * reflecting setup. For transmission the same holds of f / (eta_l^2 (1 - F)): the BTDF's
 * Fresnel factor is Schlick's on the incident side's cosine, as the dielectric's, which
 * is not symmetric, and its eta_l^2 is the Jacobian's. */
static void evaluate_is_reciprocal(void **state)
{
    (void)state;
    const int materials[] = {METAL_03, METAL_10, DIELECTRIC_05, MIXED_04, GLASS_05, HALF_GLASS_07};
    enum { PAIRS = 4096 };
    frame f = frame_around(normalized(tilted_normal));
    gpu_material_query *queries = malloc(2 * PAIRS * sizeof *queries);
    assert_non_null(queries);
    uint64_t seed = 600;
    const float u[4] = {0.5f, 0.5f, 0.5f, 0.5f};
    for (int i = 0; i < PAIRS; i++) {
        bool transmit = i % 2 == 1;
        int material = transmit ? (i / 2 % 2 ? GLASS_05 : HALF_GLASS_07) : materials[i / 2 % 6];
        vec a = to_world(&f, normalized(make_vec(uniform(&seed) - 0.5, uniform(&seed) - 0.5, 0.05 + uniform(&seed))));
        vec b = to_world(&f, normalized(make_vec(uniform(&seed) - 0.5, uniform(&seed) - 0.5, 0.05 + uniform(&seed))));
        if (transmit)
            b = add(b, scale(f.n, -2 * dot(b, f.n)));   /* below: the other side */
        /* Forward: the ray arrives along -a at the front; backward: along -b, from b's side. */
        queries[2 * i] = (gpu_material_query){.front_face = true, .material = (uint32_t)material};
        store(queries[2 * i].direction, scale(a, -1));
        store(queries[2 * i].normal, f.n);
        store(queries[2 * i].shading, f.n);
        store(queries[2 * i].to_light, b);
        memcpy(queries[2 * i].u, u, sizeof u);
        queries[2 * i + 1] = queries[2 * i];
        vec facing = transmit ? scale(f.n, -1) : f.n;
        queries[2 * i + 1].front_face = !transmit;
        store(queries[2 * i + 1].direction, scale(b, -1));
        store(queries[2 * i + 1].normal, facing);
        store(queries[2 * i + 1].shading, facing);
        store(queries[2 * i + 1].to_light, a);
    }
    gpu_material_result *r = run(queries, 2 * PAIRS);
    int compared = 0;
    for (int i = 0; i < PAIRS; i++) {
        /* Forward: view v = a, light l = b; backward the other way round. */
        vec v = load(queries[2 * i + 1].to_light), l = load(queries[2 * i].to_light);
        double forward = r[2 * i].evaluate[1] / fabs(dot(l, f.n));
        double backward = r[2 * i + 1].evaluate[1] / fabs(dot(v, f.n));
        if (i % 2 == 1) {
            /* v outside (index 1), l inside (1.5): the facet between them. */
            vec h = normalized(add(scale(v, 1 / 1.5), l));
            h = dot(h, f.n) < 0 ? scale(h, -1) : h;
            forward /= 1.5 * 1.5 * (1 - fresnel(fabs(dot(v, h)), 1 / 1.5));
            backward /= 1 * (1 - fresnel(fabs(dot(l, h)), 1.5));
        }
        if (forward < 1e-6 && backward < 1e-6)
            continue;
        assert_relative(forward, backward, 2e-3);
        compared++;
    }
    print_message("%d of %d pairs compared (the others: no refraction joins them)\n", compared, PAIRS);
    /* Every reflection pair, and the transmission pairs that a facet refracts into each other. */
    assert_true(compared > PAIRS * 5 / 8);
    free(r);
    free(queries);
}

/* ---- the smooth limit -------------------------------------------------------------- */

/* Roughness 0 samples as the fuzz-0 metal and the dielectric do (white, where the metal's
 * Fresnel term is 1): the same direction, weight and absorption for the same numbers,
 * from outside and inside, with no light sampling and no density for MIS. Numbers within
 * 1e-4 of the Fresnel reflectance are left out: the two may round the choice apart. */
static void roughness_zero_is_the_metal_and_the_dielectric(void **state)
{
    (void)state;
    enum { COUNT = 1 << 14 };
    gpu_material_query *queries = malloc(4 * COUNT * sizeof *queries);
    assert_non_null(queries);
    frame f = frame_around(normalized(tilted_normal));
    uint64_t seed = 700;
    int used = 0;
    for (int i = 0; i < COUNT; i++) {
        bool glass = i % 2 == 1, inside = glass && i % 4 == 3;
        double angle = acos(0.02 + 0.98 * uniform(&seed)), phi = 2 * M_PI * uniform(&seed);
        vec view = to_world(&f, make_vec(sin(angle) * cos(phi), sin(angle) * sin(phi), cos(angle)));
        float u[4] = {uniform(&seed), uniform(&seed), uniform(&seed), uniform(&seed)};
        double reflectance = fresnel(cos(angle), inside ? 1.5 : 1 / 1.5);
        if (glass && fabs(u[3] - reflectance) < 1e-4)
            continue;
        for (int k = 0; k < 2; k++) {
            gpu_material_query *q = &queries[2 * used + k];
            uint32_t material = glass ? (k ? DIELECTRIC_15 : SMOOTH_GLASS) : (k ? FUZZLESS_METAL : SMOOTH_METAL);
            *q = query_from(material, view, f.n, !inside);
            memcpy(q->u, u, sizeof u);
        }
        used++;
    }
    gpu_material_result *r = run(queries, 2 * used);
    for (int i = 0; i < used; i++) {
        const gpu_material_result *pbr = &r[2 * i], *old = &r[2 * i + 1];
        assert_int_equal(pbr->absorbed, old->absorbed);
        assert_false(pbr->light_sampled);
        assert_true(pbr->pdf == 0);
        for (int c = 0; c < 3; c++) {
            assert_close(pbr->direction[c], old->direction[c], 2e-6);
            assert_close(pbr->weight[c], old->weight[c], 2e-6);
        }
        assert_true(pbr->evaluate_pdf == 0 && pbr->evaluate[0] == 0);
    }
    free(r);
    free(queries);
}

/* ---- the Ray Tracing books' metal and glass ---------------------------------------------- */

/* A fuzzy metal (fuzz 1) sends the path along the mirror direction plus a point of the unit
 * ball drawn from u (glsl/sampling.glsl random_in_unit_sphere: a direction from u.xy, the
 * radius the cube root of u.z, which glsl/sampling.glsl cube_root computes without pow),
 * normalised; below the surface it absorbs. Checked against that construction in double
 * for each query, and the radii's distribution against the ball's (a mean radius of 3/4). */
static void fuzzy_metal_moves_the_mirror_direction_by_a_point_in_the_ball(void **state)
{
    (void)state;
    enum { COUNT = 4000 };
    gpu_material_query *queries = calloc(COUNT, sizeof *queries);
    assert_non_null(queries);
    frame f = frame_around(normalized(make_vec(0.2, 0.3, 1)));
    uint64_t seed = 900;
    for (int i = 0; i < COUNT; i++) {
        gpu_material_query *q = &queries[i];
        double angle = acos(0.05 + 0.95 * uniform(&seed)), phi = 2 * M_PI * uniform(&seed);
        vec view = to_world(&f, make_vec(sin(angle) * cos(phi), sin(angle) * sin(phi), cos(angle)));
        *q = query_from(FUZZY_METAL, view, f.n, true);
        for (int k = 0; k < 4; k++)
            q->u[k] = (float)uniform(&seed);
    }
    gpu_material_result *r = run(queries, COUNT);
    int compared = 0;
    double radius_sum = 0;
    for (int i = 0; i < COUNT; i++) {
        const gpu_material_query *q = &queries[i];
        vec d = make_vec(q->direction[0], q->direction[1], q->direction[2]);
        vec mirror = add(d, scale(f.n, -2 * dot(d, f.n)));
        double z = 1 - 2.0 * q->u[0], ring = sqrt(fmax(0, 1 - z * z)), turn = 2 * M_PI * q->u[1];
        double radius = cbrt((double)q->u[2]);
        radius_sum += radius;
        vec moved = add(mirror, scale(make_vec(ring * cos(turn), ring * sin(turn), z), radius));
        double length = sqrt(dot(moved, moved));
        vec expected = scale(moved, 1 / length);
        /* Near the surface's plane or a near-zero sum float rounding may decide either way. */
        if (length < 0.05 || fabs(dot(expected, f.n)) < 1e-4)
            continue;
        compared++;
        assert_int_equal(r[i].absorbed, dot(expected, f.n) <= 0);
        assert_close(r[i].direction[0], expected.x, 2e-5 / length);
        assert_close(r[i].direction[1], expected.y, 2e-5 / length);
        assert_close(r[i].direction[2], expected.z, 2e-5 / length);
    }
    assert_true(compared > COUNT * 9 / 10);
    /* The radii are the ball's: their mean is 3/4 (density 3 r^2). */
    assert_close(radius_sum / COUNT, 0.75, 0.01);
    free(r);
    free(queries);
}

/* Glass reflects where Schlick's approximation of the Fresnel reflectance, computed here in
 * double, exceeds u.w (and under total internal reflection), and refracts otherwise
 * (glsl/material_dielectric.glsl, its fifth power now by multiplication). */
static void glass_reflects_with_schlick_probability(void **state)
{
    (void)state;
    enum { COUNT = 4000 };
    gpu_material_query *queries = calloc(COUNT, sizeof *queries);
    bool *expect_reflect = calloc(COUNT, sizeof *expect_reflect);
    assert_non_null(queries);
    assert_non_null(expect_reflect);
    frame f = frame_around(normalized(make_vec(-0.1, 0.4, 1)));
    uint64_t seed = 901;
    int used = 0, reflections = 0, refractions = 0;
    while (used < COUNT) {
        bool inside = uniform(&seed) < 0.5;
        double cosine = 0.01 + 0.99 * uniform(&seed), phi = 2 * M_PI * uniform(&seed);
        double eta = inside ? 1.5 : 1 / 1.5, sine = sqrt(1 - cosine * cosine);
        double r0 = (1 - eta) / (1 + eta);
        r0 *= r0;
        double schlick = r0 + (1 - r0) * pow(1 - cosine, 5);
        float u3 = (float)uniform(&seed);
        if (fabs(u3 - schlick) < 1e-4 || fabs(eta * sine - 1) < 1e-4)
            continue;
        gpu_material_query *q = &queries[used];
        vec view = to_world(&f, make_vec(sine * cos(phi), sine * sin(phi), cosine));
        /* From inside, the ray leaves through the surface the normal faces away from. */
        *q = query_from(DIELECTRIC_15, view, f.n, !inside);
        q->u[3] = u3;
        expect_reflect[used] = eta * sine > 1 || schlick > u3;
        used++;
    }
    gpu_material_result *r = run(queries, COUNT);
    for (int i = 0; i < COUNT; i++) {
        vec got = make_vec(r[i].direction[0], r[i].direction[1], r[i].direction[2]);
        bool reflected = dot(got, f.n) > 0;   /* the view is on the normal's side */
        assert_int_equal(reflected, expect_reflect[i]);
        reflections += reflected;
        refractions += !reflected;
    }
    assert_true(reflections > 200 && refractions > 200);
    free(r);
    free(expect_reflect);
    free(queries);
}

/* ---- vertex colours ------------------------------------------------------------------ */

/* A scene of one triangle mesh in front of the camera under a white sky: a pbr material
 * whose base colour is base, times the vertex colours (each vertex colour) when given. */
static void coloured_triangle(scene *s, const float base[3], const float (*colors)[3])
{
    scene_defaults(s);
    s->render.width = s->render.height = 16;
    s->render.samples_per_pixel = 16;
    s->render.max_depth = 4;
    s->sky.type = SKY_CONSTANT;
    s->sky.bottom[0] = s->sky.bottom[1] = s->sky.bottom[2] = 1;
    s->camera.look_from[2] = 3;
    s->camera.vertical_fov_degrees = 30;
    scene_material m = scene_material_defaults();
    m.type = MATERIAL_PBR;
    memcpy(m.albedo, base, sizeof m.albedo);
    m.roughness = 0.6f;
    m.index_of_refraction = 1.5f;
    m.vertex_colors = colors != NULL;
    assert_true(scene_add_material(s, &m) == 0);
    scene_mesh mesh = {.default_material = 0, .vertex_count = 3, .triangle_count = 1};
    const float positions[9] = {-2, -2, 0, 2, -2, 0, 0, 2, 0};
    const uint32_t indices[3] = {0, 1, 2};
    mesh.positions = malloc(sizeof positions);
    mesh.indices = malloc(sizeof indices);
    memcpy(mesh.positions, positions, sizeof positions);
    memcpy(mesh.indices, indices, sizeof indices);
    if (colors != NULL) {
        mesh.colors = malloc(9 * sizeof(float));
        memcpy(mesh.colors, colors, 9 * sizeof(float));
    }
    scene_object object = {.mesh = scene_add_mesh(s, &mesh)};
    assert_true(scene_add_object(s, &object) >= 0);
    scene_instance here = {.object = 0, .material = 0};
    scene_identity_transform(here.object_to_world);
    assert_true(scene_add_instance(s, &here) >= 0);
}

/* Renders s; the caller frees the image. */
static rt_image render_image(const scene *s)
{
    render_result result;
    rt_error error;
    if (render_scene(context, s, NULL, &result, &error) != RT_OK)
        fail_msg("%s", error.message);
    image_free(&result.aovs);
    return result.image;
}

/* Vertex colours multiply the base colour: a mesh whose vertices are all one colour
 * renders as the base colour times it (to the unsigned 16-bit fractions they are stored
 * as), and colours that differ per vertex are interpolated. */
static void vertex_colours_multiply_the_base_colour(void **state)
{
    (void)state;
    const float white[3] = {1, 1, 1}, colour[3] = {0.2f, 0.6f, 0.9f};
    const float same[3][3] = {{0.2f, 0.6f, 0.9f}, {0.2f, 0.6f, 0.9f}, {0.2f, 0.6f, 0.9f}};
    const float corners[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    scene plain, coloured, mixed;
    coloured_triangle(&plain, colour, NULL);
    coloured_triangle(&coloured, white, same);
    coloured_triangle(&mixed, white, corners);
    rt_image a = render_image(&plain), b = render_image(&coloured), c = render_image(&mixed);
    double largest = 0;
    for (size_t i = 0; i < 16 * 16 * 4; i++)
        largest = fmax(largest, fabs(a.pixels[i] - b.pixels[i]));
    assert_true(largest < 1e-4);
    const float *centre = &a.pixels[(8 * 16 + 8) * 4];
    assert_true(centre[0] < 0.5f * centre[2]);        /* the triangle's colour, not the sky's */
    /* Towards the red corner (bottom left) red leads, towards the blue one (top) blue. */
    const float *low = &c.pixels[(13 * 16 + 3) * 4], *high = &c.pixels[(1 * 16 + 8) * 4];
    assert_true(low[0] > 1.5 * low[1] && low[0] > 1.1 * low[2]);
    assert_true(high[2] > 1.5 * high[0] && high[2] > 1.5 * high[1]);
    image_free(&a);
    image_free(&b);
    image_free(&c);
    scene_free(&plain);
    scene_free(&coloured);
    scene_free(&mixed);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(metal_sampling_follows_its_density),
        cmocka_unit_test(dielectric_sampling_follows_its_density),
        cmocka_unit_test(transmission_sampling_follows_its_density),
        cmocka_unit_test(samples_carry_their_density_and_weight),
        cmocka_unit_test(values_at_the_mirror_direction_are_numbers),
        cmocka_unit_test(metal_furnace_loses_what_single_scattering_loses),
        cmocka_unit_test(rough_glass_furnace_loses_what_single_scattering_loses),
        cmocka_unit_test(evaluate_is_reciprocal),
        cmocka_unit_test(roughness_zero_is_the_metal_and_the_dielectric),
        cmocka_unit_test(fuzzy_metal_moves_the_mirror_direction_by_a_point_in_the_ball),
        cmocka_unit_test(glass_reflects_with_schlick_probability),
        cmocka_unit_test(vertex_colours_multiply_the_base_colour),
    };
    return cmocka_run_group_tests(tests, set_up, tear_down);
}
