/* pack_test_scenes.h: the test data the packer's unit tests share (test_pack.c,
 * test_pack_lights.c): a reproducible random number, materials and a random scene of
 * world spheres. Include after support.h. */
#ifndef RT_PACK_TEST_SCENES_H
#define RT_PACK_TEST_SCENES_H

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

#endif
