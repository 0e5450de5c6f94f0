/* pack_test_scenes.h: the test data the packer's unit tests share (test_pack.c,
 * test_pack_lights.c, test_pack_threaded.c): a reproducible random number, materials, a
 * random scene of world spheres, random rays and the brute-force sphere test in double.
 * Include after support.h. */
#ifndef RT_PACK_TEST_SCENES_H
#define RT_PACK_TEST_SCENES_H

#include <math.h>

#include "scene.h"

/* A number in [0, 1) from the splitmix64 sequence of support.h (the test data). */
static uint64_t random_state;
static inline double random_unit(void)
{
    return (double)(splitmix64_next(&random_state) >> 11) / 9007199254740992.0;
}

/* Adds a material named name of the type with albedo (r, g, b), emission 4x that, fuzz
 * 0.25 and index of refraction 1.5. */
static inline void add_material(scene *s, const char *name, int type, float r, float g, float b)
{
    scene_material m = scene_material_defaults();
    snprintf(m.name, sizeof m.name, "%s", name);
    m.type = type;
    m.albedo[0] = r, m.albedo[1] = g, m.albedo[2] = b;
    m.fuzz = 0.25f;
    m.index_of_refraction = 1.5f;
    m.emission[0] = 4 * r, m.emission[1] = 4 * g, m.emission[2] = 4 * b;
    assert_true(scene_add_material(s, &m) >= 0);
}

/* Makes *s a scene of four materials (lambertian, metal, dielectric, emissive) and
 * sphere_count random world spheres using them in turn, from seed; the caller frees it
 * (scene_free). random_unit() goes on from there. */
static inline void random_scene(scene *s, int sphere_count, uint64_t seed)
{
    scene_defaults(s);
    random_state = seed;
    add_material(s, "a", MATERIAL_LAMBERTIAN, 0.1f, 0.2f, 0.3f);
    add_material(s, "b", MATERIAL_METAL, 0.4f, 0.5f, 0.6f);
    add_material(s, "c", MATERIAL_DIELECTRIC, 1, 1, 1);
    add_material(s, "d", MATERIAL_EMISSIVE, 0.7f, 0.8f, 0.9f);
    for (int i = 0; i < sphere_count; i++) {
        scene_sphere sphere = {
            .center = {(float)(random_unit() * 20 - 10), (float)(random_unit() * 20 - 10),
                       (float)(random_unit() * 20 - 10)},
            .radius = (float)(0.05 + random_unit() * 1.5),
            .material = i % 4,
        };
        assert_true(scene_add_sphere(s, &sphere) >= 0);
    }
}

/* Nearest root in (0, infinity) of a sphere (centre, radius) along a unit direction, in
 * double, or INFINITY. */
static inline double sphere_hit(const float *sphere, const double origin[3], const double direction[3])
{
    double oc[3], b = 0, c = 0;
    for (int i = 0; i < 3; i++) {
        oc[i] = origin[i] - sphere[i];
        b += oc[i] * direction[i];
        c += oc[i] * oc[i];
    }
    c -= (double)sphere[3] * sphere[3];
    double discriminant = b * b - c;
    if (discriminant < 0)
        return INFINITY;
    double root = sqrt(discriminant);
    if (-b - root > 0)
        return -b - root;
    if (-b + root > 0)
        return -b + root;
    return INFINITY;
}

/* A random unit ray around random_scene's spheres, in float (of, df) and the same values
 * in double (o, d); every tenth lies in a coordinate plane or along an axis (zero
 * direction components, where the box test divides by zero). */
static inline void random_ray(int r, double o[3], double d[3], float of[3], float df[3])
{
    double length = 0;
    do {
        length = 0;
        for (int i = 0; i < 3; i++) {
            o[i] = random_unit() * 30 - 15;
            d[i] = random_unit() * 2 - 1;
            if (r % 10 == 0 && i != r % 3)
                d[i] = 0;
            length += d[i] * d[i];
        }
    } while (length == 0);
    length = sqrt(length);
    for (int i = 0; i < 3; i++) {
        of[i] = (float)o[i];
        df[i] = (float)(d[i] / length);
        o[i] = of[i];
        d[i] = df[i];
    }
}

#endif
