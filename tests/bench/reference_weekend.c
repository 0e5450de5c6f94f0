/* reference_weekend.c: the plain C reference of `make bench` (issue #6): renders
 * scenes/weekend.txt on the CPU so that every bench run can report rtspheres' speed as a
 * ratio to it, measured on the same machine at the same time.
 *
 * What "plain" means here, on purpose: float32 math, one straightforward loop over all
 * spheres for every ray (no acceleration structure, no hand-written SIMD), OpenMP over
 * image rows, built with -O3 -march=native -fopenmp. Everything else follows rtspheres'
 * own tracer (the GLSL modules of glsl/) so that the two do the same work per path segment:
 *   - the camera of core/camera.c (thin lens, vertical fov, focus distance);
 *   - the sky gradient mix(bottom, top, 0.5 (y + 1));
 *   - Lambertian (normal + unit vector), metal (reflection + fuzz * point in the unit
 *     ball, absorbed below the surface) and dielectric (Schlick's reflectance);
 *   - the same random numbers: a hash of (pixel, sample, seed, bounce * 8 + stream),
 *     so both renderers draw the same samples and their images agree in the mean;
 *   - the same float32-safe sphere intersection and ray offset (the radius-1000 ground
 *     sphere needs them), Russian roulette from the same depth (default 4), at most
 *     --max-depth segments per sample.
 * A path segment is one ray cast from the camera or from a bounce, counted where it is
 * traced, as the shader counts statistics.x. The weekend scene has no lights (its
 * gradient sky is not sampled as a light), so rtspheres casts no shadow rays in it and
 * neither does this: segments/s compare like with like.
 *
 * The scene comes from the file itself through a small reader of exactly the statements
 * weekend.txt uses (set, render, camera, sky gradient, material lambertian/metal/
 * dielectric, sphere; `$name` variables as whole numbers). Anything else is an error,
 * so the reference can never silently render a different scene. It deliberately does
 * not link the project's parser: a reference that shares code with what it measures
 * could share its bugs too, and the bench compares the two images' means as a check.
 *
 * usage: reference_weekend SCENE -o OUT.pfm [--size WxH] [--spp N] [--max-depth N]
 *                          [--seed N] [--roulette-depth N]
 * Prints one summary line on stdout, in the words of rtspheres' own summary:
 *   reference: SCENE -> OUT: WxH, N spp in S s (X samples/s, Y path segments/s,
 *   T threads); mean R G B
 * The image is a PFM (linear float RGB), the time covers the render loop only.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <omp.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_NAME 64
#define MAX_VARIABLES 64
#define MAX_TOKENS 32
#define PI_F 3.14159265358979f

typedef struct {
    float x, y, z;
} vec3;

enum material_kind { LAMBERTIAN, METAL, DIELECTRIC };

typedef struct {
    char name[MAX_NAME];
    enum material_kind kind;
    vec3 albedo;
    float fuzz;
    float ior;
} material;

typedef struct {
    vec3 center;
    float radius;
    int material;
} sphere;

typedef struct {
    char name[MAX_NAME];
    float value;
} variable;

typedef struct {
    int width, height, samples_per_pixel, max_depth, roulette_depth;
    uint32_t seed;
    vec3 look_from, look_at, up;
    float fov_degrees, aperture, focus_distance;
    vec3 sky_bottom, sky_top;
    float sky_intensity;
    material *materials;
    int material_count;
    sphere *spheres;
    int sphere_count;
    variable variables[MAX_VARIABLES];
    int variable_count;
} weekend_scene;

/* The camera of core/camera.c, reduced to what a ray needs. */
typedef struct {
    vec3 origin, lower_left, horizontal, vertical, u, v;
    float lens_radius;
} camera_frame;

/* ---- small vector helpers; each returns the obvious result ---------------------- */

/* Returns a + b. */
static inline vec3 add(vec3 a, vec3 b) { return (vec3){a.x + b.x, a.y + b.y, a.z + b.z}; }
/* Returns a - b. */
static inline vec3 sub(vec3 a, vec3 b) { return (vec3){a.x - b.x, a.y - b.y, a.z - b.z}; }
/* Returns s * a. */
static inline vec3 scale(vec3 a, float s) { return (vec3){s * a.x, s * a.y, s * a.z}; }
/* Returns the componentwise product of a and b. */
static inline vec3 mul(vec3 a, vec3 b) { return (vec3){a.x * b.x, a.y * b.y, a.z * b.z}; }
/* Returns the dot product of a and b. */
static inline float dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
/* Returns the cross product a x b. */
static inline vec3 cross(vec3 a, vec3 b)
{
    return (vec3){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
/* Returns a scaled to unit length. */
static inline vec3 normalize(vec3 a) { return scale(a, 1.0f / sqrtf(dot(a, a))); }
/* Returns the mirror image of incident i about the unit normal n (GLSL reflect). */
static inline vec3 reflect(vec3 i, vec3 n) { return sub(i, scale(n, 2.0f * dot(n, i))); }
/* Returns the refraction of unit i through unit n with index ratio eta, or zero on total
 * internal reflection (GLSL refract; the caller has already ruled that case out). */
static inline vec3 refract(vec3 i, vec3 n, float eta)
{
    float cosine = dot(n, i);
    float k = 1.0f - eta * eta * (1.0f - cosine * cosine);
    if (k < 0.0f)
        return (vec3){0, 0, 0};
    return sub(scale(i, eta), scale(n, eta * cosine + sqrtf(k)));
}

/* ---- random numbers: glsl/random.glsl's hash, in C ------------------------------ */

/* Mixes four 32-bit words into four (the pcg4d-style hash of glsl/random.glsl: two rounds
 * of multiply-add across components); returns the mixed words in v. */
static inline void hash4(uint32_t v[4])
{
    for (int i = 0; i < 4; i++)
        v[i] = v[i] * 1664525u + 1013904223u;
    for (int round = 0; round < 2; round++) {
        v[0] += v[1] * v[3];
        v[1] += v[2] * v[0];
        v[2] += v[0] * v[1];
        v[3] += v[1] * v[2];
        for (int i = 0; i < 4; i++)
            v[i] ^= v[i] >> 16;
    }
}

/* Returns the user seed spread over all bits, as random_seed_hash() does. */
static uint32_t seed_hash(uint32_t seed)
{
    uint32_t v[4] = {seed, 0x9e3779b9u, 0x85ebca6bu, 0xc2b2ae35u};
    hash4(v);
    return v[0];
}

/* Fills out[4] with uniform numbers in [0, 1) (24 bits) for one dimension of one sample of
 * one pixel; the same numbers as random_numbers() in the shader. */
static inline void random4(int x, int y, uint32_t sample, uint32_t seed_hash_value, uint32_t dimension,
                           float out[4])
{
    uint32_t v[4] = {(uint32_t)x, (uint32_t)y, sample, seed_hash_value ^ dimension};
    hash4(v);
    for (int i = 0; i < 4; i++)
        out[i] = (float)(v[i] >> 8) * (1.0f / 16777216.0f);
}

/* Returns a uniform direction on the unit sphere from two uniform numbers. */
static inline vec3 random_unit_vector(float u0, float u1)
{
    float z = 1.0f - 2.0f * u0;
    float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    float phi = 2.0f * PI_F * u1;
    return (vec3){r * cosf(phi), r * sinf(phi), z};
}

/* ---- the scene reader ------------------------------------------------------------ */

/* Prints "reference: FILE:LINE: message" to stderr and exits with status 2 (bad input,
 * as rtspheres does). */
static void fail_at(const char *path, int line, const char *message, const char *detail)
{
    fprintf(stderr, "reference: %s:%d: %s%s%s\n", path, line, message, detail ? ": " : "", detail ? detail : "");
    exit(2);
}

/* Returns the number a token stands for: a plain decimal number or `$name` of a `set`
 * variable. Exits with a message for anything else (expressions are not in this subset). */
static float number_token(weekend_scene *scene, const char *token, const char *path, int line)
{
    if (token[0] == '$') {
        for (int i = 0; i < scene->variable_count; i++)
            if (strcmp(scene->variables[i].name, token + 1) == 0)
                return scene->variables[i].value;
        fail_at(path, line, "unknown variable", token);
    }
    char *end;
    float value = strtof(token, &end);
    if (end == token || *end != '\0')
        fail_at(path, line, "not a plain number (expressions are outside this reader's subset)", token);
    return value;
}

/* Reads three numbers from tokens[at..at+2]; returns them as a vector. */
static vec3 vector_tokens(weekend_scene *scene, char **tokens, int count, int at, const char *path, int line)
{
    if (at + 3 > count)
        fail_at(path, line, "expected three numbers", NULL);
    return (vec3){number_token(scene, tokens[at], path, line), number_token(scene, tokens[at + 1], path, line),
                  number_token(scene, tokens[at + 2], path, line)};
}

/* Returns the index of the material called name, or -1. */
static int find_material(const weekend_scene *scene, const char *name)
{
    for (int i = 0; i < scene->material_count; i++)
        if (strcmp(scene->materials[i].name, name) == 0)
            return i;
    return -1;
}

/* Appends one element to a growing array (*items, *count), doubling its capacity;
 * returns a pointer to the new, zeroed element. */
static void *append(void **items, int *count, int *capacity, size_t size)
{
    if (*count == *capacity) {
        *capacity = *capacity ? 2 * *capacity : 64;
        void *grown = realloc(*items, (size_t)*capacity * size);
        if (grown == NULL) {
            fprintf(stderr, "reference: out of memory\n");
            exit(1);
        }
        *items = grown;
    }
    void *item = (char *)*items + (size_t)(*count)++ * size;
    memset(item, 0, size);
    return item;
}

/* Handles one statement, already split into tokens; exits with a message on anything
 * outside the subset weekend.txt uses. */
static void read_statement(weekend_scene *scene, char **tokens, int count, const char *path, int line,
                           int *material_capacity, int *sphere_capacity)
{
    const char *keyword = tokens[0];
    if (strcmp(keyword, "set") == 0 && count == 3) {
        if (scene->variable_count == MAX_VARIABLES)
            fail_at(path, line, "too many variables", NULL);
        variable *v = &scene->variables[scene->variable_count++];
        snprintf(v->name, sizeof v->name, "%s", tokens[1]);
        v->value = number_token(scene, tokens[2], path, line);
    } else if (strcmp(keyword, "render") == 0) {
        for (int i = 1; i < count; i++) {
            if (strcmp(tokens[i], "size") == 0 && i + 2 < count) {
                scene->width = (int)number_token(scene, tokens[++i], path, line);
                scene->height = (int)number_token(scene, tokens[++i], path, line);
            } else if (strcmp(tokens[i], "spp") == 0 && i + 1 < count) {
                scene->samples_per_pixel = (int)number_token(scene, tokens[++i], path, line);
            } else if (strcmp(tokens[i], "depth") == 0 && i + 1 < count) {
                scene->max_depth = (int)number_token(scene, tokens[++i], path, line);
            } else if (strcmp(tokens[i], "seed") == 0 && i + 1 < count) {
                scene->seed = (uint32_t)number_token(scene, tokens[++i], path, line);
            } else {
                fail_at(path, line, "unknown render setting", tokens[i]);
            }
        }
    } else if (strcmp(keyword, "camera") == 0) {
        for (int i = 1; i < count; i++) {
            if (strcmp(tokens[i], "from") == 0) {
                scene->look_from = vector_tokens(scene, tokens, count, i + 1, path, line);
                i += 3;
            } else if (strcmp(tokens[i], "at") == 0) {
                scene->look_at = vector_tokens(scene, tokens, count, i + 1, path, line);
                i += 3;
            } else if (strcmp(tokens[i], "up") == 0) {
                scene->up = vector_tokens(scene, tokens, count, i + 1, path, line);
                i += 3;
            } else if (strcmp(tokens[i], "fov") == 0 && i + 1 < count) {
                scene->fov_degrees = number_token(scene, tokens[++i], path, line);
            } else if (strcmp(tokens[i], "aperture") == 0 && i + 1 < count) {
                scene->aperture = number_token(scene, tokens[++i], path, line);
            } else if (strcmp(tokens[i], "focus") == 0 && i + 1 < count) {
                scene->focus_distance = number_token(scene, tokens[++i], path, line);
            } else {
                fail_at(path, line, "unknown camera setting", tokens[i]);
            }
        }
    } else if (strcmp(keyword, "sky") == 0 && count >= 8 && strcmp(tokens[1], "gradient") == 0) {
        scene->sky_bottom = vector_tokens(scene, tokens, count, 2, path, line);
        scene->sky_top = vector_tokens(scene, tokens, count, 5, path, line);
        if (count == 10 && strcmp(tokens[8], "intensity") == 0)
            scene->sky_intensity = number_token(scene, tokens[9], path, line);
        else if (count != 8)
            fail_at(path, line, "unknown sky setting", tokens[8]);
    } else if (strcmp(keyword, "material") == 0 && count >= 4) {
        material *m = append((void **)&scene->materials, &scene->material_count, material_capacity, sizeof *m);
        snprintf(m->name, sizeof m->name, "%s", tokens[1]);
        if (strcmp(tokens[2], "lambertian") == 0 && count == 6) {
            m->kind = LAMBERTIAN;
            m->albedo = vector_tokens(scene, tokens, count, 3, path, line);
        } else if (strcmp(tokens[2], "metal") == 0 && (count == 6 || (count == 8 && strcmp(tokens[6], "fuzz") == 0))) {
            m->kind = METAL;
            m->albedo = vector_tokens(scene, tokens, count, 3, path, line);
            m->fuzz = count == 8 ? number_token(scene, tokens[7], path, line) : 0.0f;
        } else if (strcmp(tokens[2], "dielectric") == 0 && count == 4) {
            m->kind = DIELECTRIC;
            m->ior = number_token(scene, tokens[3], path, line);
        } else {
            fail_at(path, line, "material outside this reader's subset", tokens[2]);
        }
    } else if (strcmp(keyword, "sphere") == 0 && count == 6) {
        sphere *s = append((void **)&scene->spheres, &scene->sphere_count, sphere_capacity, sizeof *s);
        s->center = vector_tokens(scene, tokens, count, 1, path, line);
        s->radius = number_token(scene, tokens[4], path, line);
        s->material = find_material(scene, tokens[5]);
        if (s->material < 0)
            fail_at(path, line, "unknown material", tokens[5]);
    } else {
        fail_at(path, line, "statement outside the weekend subset this reference reads", keyword);
    }
}

/* Reads the scene file at path into scene (defaults first: white sky intensity 1, the
 * scene file's render line may then set size, spp, depth and seed). Exits on error. */
static void read_scene(const char *path, weekend_scene *scene)
{
    FILE *file = fopen(path, "r");
    if (file == NULL) {
        perror(path);
        exit(2);
    }
    memset(scene, 0, sizeof *scene);
    scene->width = 1200;
    scene->height = 675;
    scene->samples_per_pixel = 8;
    scene->max_depth = 50;
    scene->roulette_depth = 4;
    scene->seed = 1;
    scene->sky_intensity = 1.0f;
    scene->fov_degrees = 20.0f;
    scene->up = (vec3){0, 1, 0};
    int material_capacity = 0, sphere_capacity = 0;
    char text[4096];
    int line = 0;
    while (fgets(text, sizeof text, file) != NULL) {
        line++;
        char *comment = strchr(text, '#');
        if (comment != NULL)
            *comment = '\0';
        char *tokens[MAX_TOKENS];
        int count = 0;
        for (char *token = strtok(text, " \t\r\n"); token != NULL; token = strtok(NULL, " \t\r\n")) {
            if (count == MAX_TOKENS)
                fail_at(path, line, "too many words", NULL);
            tokens[count++] = token;
        }
        if (count > 0)
            read_statement(scene, tokens, count, path, line, &material_capacity, &sphere_capacity);
    }
    fclose(file);
    if (scene->sphere_count == 0)
        fail_at(path, line, "no spheres", NULL);
}

/* ---- rendering ------------------------------------------------------------------- */

/* Returns the camera frame of core/camera.c for the scene at its image size. */
static camera_frame make_camera(const weekend_scene *scene)
{
    camera_frame frame;
    vec3 back = sub(scene->look_from, scene->look_at);
    float view_distance = sqrtf(dot(back, back));
    vec3 w = scale(back, 1.0f / view_distance);
    vec3 u = normalize(cross(scene->up, w));
    vec3 v = cross(w, u);
    float focus = scene->focus_distance > 0 ? scene->focus_distance : view_distance;
    float half_height = tanf(scene->fov_degrees * (PI_F / 180.0f) * 0.5f) * focus;
    float half_width = half_height * (float)scene->width / (float)scene->height;
    frame.origin = scene->look_from;
    frame.u = u;
    frame.v = v;
    frame.horizontal = scale(u, 2 * half_width);
    frame.vertical = scale(v, 2 * half_height);
    frame.lower_left = sub(sub(sub(scene->look_from, scale(u, half_width)), scale(v, half_height)), scale(w, focus));
    frame.lens_radius = scene->aperture * 0.5f;
    return frame;
}

/* Returns the nearest t in (0, t_max) where the ray origin + t * direction (direction of
 * unit length) meets the sphere, or INFINITY. The discriminant comes from the squared
 * distance of the centre to the ray's closest point, as in the shader: with float32 the
 * textbook form loses the radius-1000 ground sphere to cancellation. */
static inline float intersect_sphere(const sphere *s, vec3 origin, vec3 direction, float t_max)
{
    vec3 to_origin = sub(origin, s->center);
    float b = dot(to_origin, direction);
    vec3 closest_offset = sub(to_origin, scale(direction, b));
    float radius_squared = s->radius * s->radius;
    float discriminant = radius_squared - dot(closest_offset, closest_offset);
    if (discriminant < 0.0f)
        return INFINITY;
    float root = sqrtf(discriminant);
    float c = dot(to_origin, to_origin) - radius_squared;
    float q = -b - (b >= 0.0f ? root : -root);
    float t_near = c / q, t_far = q;
    if (t_near > t_far) {
        float swap = t_near;
        t_near = t_far;
        t_far = swap;
    }
    if (t_near > 0.0f && t_near < t_max)
        return t_near;
    if (t_far > 0.0f && t_far < t_max)
        return t_far;
    return INFINITY;
}

/* Returns the index of the nearest sphere the ray meets (its distance in *t), or -1: the
 * brute-force loop over every sphere that this reference exists to time. */
static inline int trace(const weekend_scene *scene, vec3 origin, vec3 direction, float *t)
{
    int nearest = -1;
    float t_nearest = INFINITY;
    for (int i = 0; i < scene->sphere_count; i++) {
        float t_sphere = intersect_sphere(&scene->spheres[i], origin, direction, t_nearest);
        if (t_sphere < t_nearest) {
            t_nearest = t_sphere;
            nearest = i;
        }
    }
    *t = t_nearest;
    return nearest;
}

/* Returns the offset a new ray leaving p starts at, grown with |p| because float32
 * spacing grows with it (the shader's ray_offset). */
static inline float ray_offset(vec3 p)
{
    return 1e-4f * (1.0f + fmaxf(fabsf(p.x), fmaxf(fabsf(p.y), fabsf(p.z))));
}

/* Returns Schlick's approximation of the dielectric's reflectance. */
static inline float schlick_reflectance(float cosine, float eta_ratio)
{
    float r0 = (1.0f - eta_ratio) / (1.0f + eta_ratio);
    r0 = r0 * r0;
    return r0 + (1.0f - r0) * powf(1.0f - cosine, 5.0f);
}

/* Traces one sample (camera ray and its bounces) of pixel (x, row) (row 0 at the top);
 * returns its radiance and adds the segments it traced to *segments. */
static vec3 render_sample(const weekend_scene *scene, const camera_frame *camera, uint32_t seed_hash_value, int x,
                          int row, uint32_t sample, uint64_t *segments)
{
    float u[4];
    random4(x, row, sample, seed_hash_value, 0u, u);
    float film_x = ((float)x + u[0]) / (float)scene->width;
    float film_y = ((float)(scene->height - 1 - row) + u[1]) / (float)scene->height;
    float lens_r = camera->lens_radius * sqrtf(u[2]), lens_phi = 2.0f * PI_F * u[3];
    vec3 origin = add(camera->origin, add(scale(camera->u, lens_r * cosf(lens_phi)),
                                          scale(camera->v, lens_r * sinf(lens_phi))));
    vec3 direction = normalize(sub(add(camera->lower_left, add(scale(camera->horizontal, film_x),
                                                               scale(camera->vertical, film_y))),
                                   origin));
    vec3 throughput = {1, 1, 1}, radiance = {0, 0, 0};
    for (uint32_t bounce = 1;; bounce++) {
        float t;
        int hit = trace(scene, origin, direction, &t);
        (*segments)++;
        random4(x, row, sample, seed_hash_value, bounce * 8u + 1u, u);
        if (hit < 0) {
            float blend = 0.5f * (direction.y + 1.0f);
            vec3 sky = add(scale(scene->sky_bottom, 1.0f - blend), scale(scene->sky_top, blend));
            return add(radiance, mul(throughput, scale(sky, scene->sky_intensity)));
        }
        const sphere *s = &scene->spheres[hit];
        const material *m = &scene->materials[s->material];
        vec3 p = add(origin, scale(direction, t));
        vec3 outward = scale(sub(p, s->center), 1.0f / s->radius);
        int front_face = dot(direction, outward) < 0.0f;
        vec3 normal = front_face ? outward : scale(outward, -1.0f);
        vec3 next;
        if (m->kind == LAMBERTIAN) {
            // normal + a uniform unit vector is cosine-distributed about the normal.
            next = add(normal, random_unit_vector(u[0], u[1]));
            float length_squared = dot(next, next);
            next = length_squared > 1e-12f ? scale(next, 1.0f / sqrtf(length_squared)) : normal;
            if (dot(next, normal) <= 0.0f)
                next = reflect(next, normal);
            throughput = mul(throughput, m->albedo);
        } else if (m->kind == METAL) {
            vec3 in_ball = scale(random_unit_vector(u[0], u[1]), cbrtf(u[2]));
            next = normalize(add(reflect(direction, normal), scale(in_ball, m->fuzz)));
            throughput = mul(throughput, m->albedo);
            if (dot(next, normal) <= 0.0f)
                return radiance;   // scattered below the surface: absorbed
        } else {
            float eta_ratio = front_face ? 1.0f / m->ior : m->ior;
            float cosine = fminf(-dot(direction, normal), 1.0f);
            float sine = sqrtf(fmaxf(0.0f, 1.0f - cosine * cosine));
            if (eta_ratio * sine > 1.0f || schlick_reflectance(cosine, eta_ratio) > u[3])
                next = reflect(direction, normal);
            else
                next = refract(direction, normal, eta_ratio);
        }
        float side = dot(next, normal) > 0.0f ? 1.0f : -1.0f;
        origin = add(p, scale(normal, side * ray_offset(p)));
        direction = next;
        if (bounce + 1 > (uint32_t)scene->max_depth)
            return radiance;
        if (bounce + 1 > (uint32_t)scene->roulette_depth) {
            // Unbiased Russian roulette: survivors carry the weight of the paths that ended.
            float survival = fmaxf(throughput.x, fmaxf(throughput.y, throughput.z));
            survival = fminf(fmaxf(survival, 0.05f), 1.0f);
            random4(x, row, sample, seed_hash_value, (bounce + 1) * 8u + 2u, u);
            if (u[0] >= survival)
                return radiance;
            throughput = scale(throughput, 1.0f / survival);
        }
    }
}

/* Writes a width x height RGB float image (row 0 at the top) as a little-endian PFM
 * (rows bottom to top, as the format has it); returns 0, or -1 with errno set. */
static int write_pfm(const char *path, const float *pixels, int width, int height)
{
    FILE *file = fopen(path, "wb");
    if (file == NULL)
        return -1;
    fprintf(file, "PF\n%d %d\n-1.0\n", width, height);
    int ok = 1;
    for (int row = height - 1; row >= 0 && ok; row--)
        ok = fwrite(pixels + (size_t)row * width * 3, sizeof(float) * 3, (size_t)width, file) == (size_t)width;
    if (fclose(file) != 0)
        ok = 0;
    return ok ? 0 : -1;
}

/* Returns seconds on the monotonic clock. */
static double now_seconds(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Prints the usage and exits with status 2. */
static void usage(void)
{
    fprintf(stderr, "usage: reference_weekend SCENE -o OUT.pfm [--size WxH] [--spp N] [--max-depth N]\n"
                    "                         [--seed N] [--roulette-depth N]\n");
    exit(2);
}

/* Reads the options into scene (they win over the file's render line) and returns the
 * output path; exits with the usage on anything it does not know. */
static const char *read_options(int argc, char **argv, weekend_scene *scene)
{
    const char *output = NULL;
    for (int i = 2; i < argc; i++) {
        const char *option = argv[i];
        if (i + 1 >= argc)
            usage();
        const char *value = argv[++i];
        if (strcmp(option, "-o") == 0) {
            output = value;
        } else if (strcmp(option, "--size") == 0) {
            if (sscanf(value, "%dx%d", &scene->width, &scene->height) != 2)
                usage();
        } else if (strcmp(option, "--spp") == 0) {
            scene->samples_per_pixel = atoi(value);
        } else if (strcmp(option, "--max-depth") == 0) {
            scene->max_depth = atoi(value);
        } else if (strcmp(option, "--seed") == 0) {
            scene->seed = (uint32_t)strtoul(value, NULL, 10);
        } else if (strcmp(option, "--roulette-depth") == 0) {
            scene->roulette_depth = atoi(value);
        } else {
            usage();
        }
    }
    if (output == NULL || scene->width < 1 || scene->height < 1 || scene->samples_per_pixel < 1
        || scene->max_depth < 1 || scene->roulette_depth < 0)
        usage();
    return output;
}

/* Renders the scene named on the command line, writes the PFM and prints the summary;
 * returns 0, 1 on a write failure, 2 on bad input. */
int main(int argc, char **argv)
{
    if (argc < 2)
        usage();
    weekend_scene scene;
    read_scene(argv[1], &scene);
    const char *output = read_options(argc, argv, &scene);
    camera_frame camera = make_camera(&scene);
    uint32_t seed_hash_value = seed_hash(scene.seed);
    int width = scene.width, height = scene.height, spp = scene.samples_per_pixel;
    float *pixels = malloc((size_t)width * height * 3 * sizeof *pixels);
    if (pixels == NULL) {
        fprintf(stderr, "reference: out of memory\n");
        return 1;
    }

    uint64_t segments = 0;
    double start = now_seconds();
    // Rows differ a lot in cost (sky above, spheres below): hand them out one at a time.
#pragma omp parallel for schedule(dynamic, 1) reduction(+ : segments)
    for (int row = 0; row < height; row++) {
        for (int x = 0; x < width; x++) {
            vec3 sum = {0, 0, 0};
            for (int sample = 0; sample < spp; sample++)
                sum = add(sum, render_sample(&scene, &camera, seed_hash_value, x, row, (uint32_t)sample, &segments));
            float *pixel = pixels + ((size_t)row * width + x) * 3;
            pixel[0] = sum.x / (float)spp;
            pixel[1] = sum.y / (float)spp;
            pixel[2] = sum.z / (float)spp;
        }
    }
    double seconds = now_seconds() - start;

    double mean[3] = {0, 0, 0};
    for (size_t i = 0; i < (size_t)width * height; i++)
        for (int c = 0; c < 3; c++)
            mean[c] += pixels[3 * i + c];
    for (int c = 0; c < 3; c++)
        mean[c] /= (double)width * height;
    if (write_pfm(output, pixels, width, height) != 0) {
        perror(output);
        free(pixels);
        return 1;
    }
    double samples = (double)width * height * spp;
    printf("reference: %s -> %s: %dx%d, %d spp in %.2f s (%.3g samples/s, %.3g path segments/s, %d threads); "
           "mean %.4f %.4f %.4f\n",
           argv[1], output, width, height, spp, seconds, samples / seconds, (double)segments / seconds,
           omp_get_max_threads(), mean[0], mean[1], mean[2]);
    free(scene.materials);
    free(scene.spheres);
    free(pixels);
    return 0;
}
