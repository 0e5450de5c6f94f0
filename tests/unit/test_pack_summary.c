/* test_pack_summary.c: what pack_scene() says a scene holds (pack.h, pack_summary), which
 * chooses the tracer variant: primitive kinds in either BVH level, instances, volumes,
 * emitters, textures and normal maps, pbr and alpha masks, lights by kind, the
 * environment; and the texel hash
 * it hands on (hash.h). Small scenes from text, their images given stand-in pixels. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hash.h"
#include "pack.h"
#include "packed_traverse.h"
#include "scene_parse.h"

#define BIT(tag) (1u << (tag))

static const char *const camera_line = "camera from 0 0 5 at 0 0 0\n";

/* Checks the summary against the texels themselves, decoded record by record: the
 * writers must note exactly what they wrote. */
static void assert_summary_matches_texels(const packed_scene *packed)
{
    uint32_t primitive_types = 0, light_types = 0;
    for (uint32_t slot = 0; slot < packed->primitive_count; slot++)
        primitive_types |= BIT(packed_primitive_type(packed, slot));
    for (uint32_t light = 0; light < packed->light_count; light++)
        light_types |= BIT(packed_uint(packed, packed->light_offset + light * PACKED_LIGHT_STRIDE, 0));
    bool emitters = false, textures = packed->texture_count > 0, normal_maps = false, volumes = false;
    bool pbr = false, alpha_mask = false;
    uint32_t material_types = 0;
    for (uint32_t m = 0; m < packed->material_count; m++) {
        uint32_t base = packed->material_offset + m * PACKED_MATERIAL_STRIDE;
        uint32_t type = packed_uint(packed, base, 0) & MATERIAL_TYPE_MASK;
        bool is_pbr = type == MATERIAL_PBR;
        bool emission = packed_float(packed, base + 1, 0) > 0 || packed_float(packed, base + 1, 1) > 0
                        || packed_float(packed, base + 1, 2) > 0;
        emitters |= type == MATERIAL_EMISSIVE || (is_pbr && emission);
        textures |= packed_uint(packed, base + 2, 1) != PACKED_NONE || packed_uint(packed, base + 2, 2) != PACKED_NONE
                    || (is_pbr && packed_uint(packed, base + 4, 3) != PACKED_NONE);
        normal_maps |= packed_uint(packed, base + 2, 3) != PACKED_NONE;
        pbr |= is_pbr;
        material_types |= BIT(type);
        alpha_mask |= (packed_uint(packed, base, 0) & MATERIAL_FLAG_ALPHA_MASK) != 0;
    }
    for (uint32_t i = 0; i < packed->instance_count; i++)
        volumes |= (packed_uint(packed, packed->instance_offset + i * PACKED_INSTANCE_STRIDE, 2) & INSTANCE_VOLUME) != 0;
    assert_int_equal(packed->summary.primitive_types, primitive_types);
    assert_int_equal(packed->summary.light_types, light_types);
    assert_int_equal(packed->summary.emitters, emitters);
    assert_int_equal(packed->summary.textures, textures);
    assert_int_equal(packed->summary.normal_maps, normal_maps);
    assert_int_equal(packed->summary.volumes, volumes);
    assert_int_equal(packed->summary.pbr, pbr);
    assert_int_equal(packed->summary.material_types, material_types);
    assert_int_equal(packed->summary.alpha_mask, alpha_mask);
    assert_int_equal(packed->summary.vertex_colors, packed_uint(packed, PACKED_HEADER_COLOR_OFFSET / 4,
                                                                PACKED_HEADER_COLOR_OFFSET % 4) != PACKED_NONE);
}

/* Parses camera_line followed by body, gives every image 2x1 grey pixels (nothing is
 * read from disk), packs it into *packed with options (NULL: defaults) and checks its
 * summary against its texels. */
static void pack_text(const char *body, const pack_options *options, packed_scene *packed)
{
    char text[4096];
    snprintf(text, sizeof text, "%s%s", camera_line, body);
    scene s;
    rt_error error = {0};
    rt_status status = scene_load_string(text, "summary.txt", NULL, &s, &error);
    if (status != RT_OK)
        fail_msg("%s", error.message);
    for (int i = 0; i < s.image_count; i++) {
        s.images[i].width = 2;
        s.images[i].height = 1;
        s.images[i].pixels = malloc(2 * 4 * sizeof(float));
        assert_non_null(s.images[i].pixels);
        for (int k = 0; k < 8; k++)
            s.images[i].pixels[k] = 0.5f;
    }
    status = pack_scene(&s, options, packed, &error);
    if (status != RT_OK)
        fail_msg("%s", error.message);
    scene_free(&s);
    assert_summary_matches_texels(packed);
}

/* A scene and the summary its packing must give. */
typedef struct summary_case {
    const char *what;
    const char *body;            /* after camera_line */
    bool keep_instances;         /* pack_options.keep_instances */
    uint32_t primitive_types, light_types;
    bool volumes, emitters, textures, normal_maps, pbr, alpha_mask;
} summary_case;

#define GREY "material grey lambertian 0.5 0.5 0.5\n"
#define LAMP "material lamp emissive 1 1 1 strength 4\n"
/* A quad and a triangle in a group turned, and placed again moved. */
#define PANELS                                                                                                         \
    GREY "sphere 0 -10 0 1 grey\n"                                                                                     \
         "group panel material grey {\n    rotate 0 1 0 30\n    quad 0 0 0  1 0 0  0 1 0\n"                            \
         "    triangle 0 0 1  1 0 1  0 1 1\n}\n"                                                                       \
         "instance panel {\n    translate 3 0 0\n}\n"

static const summary_case cases[] = {
    {.what = "spheres only",
     .body = GREY "sphere 0 0 0 1 grey\nsphere 2 0 0 1 grey\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE)},
    {.what = "every kind at the top level, no plain sphere",
     .body = GREY "moving_sphere 0 0 0  0 1 0  0.5 grey\ntriangle 0 0 0  1 0 0  0 1 0 grey\n"
                  "quad 0 0 -1  1 0 0  0 1 0 grey\n",
     .primitive_types = BIT(PRIMITIVE_MOVING_SPHERE) | BIT(PRIMITIVE_TRIANGLE) | BIT(PRIMITIVE_QUAD)},
    /* The quad and the triangle are only in the group's own BVH, placed twice with a
     * rotation and kept instanced: they count. */
    {.what = "kinds inside instances",
     .body = PANELS,
     .keep_instances = true,
     .primitive_types = BIT(PRIMITIVE_SPHERE) | BIT(PRIMITIVE_TRIANGLE) | BIT(PRIMITIVE_QUAD) | BIT(PRIMITIVE_INSTANCE)},
    /* By default both placements are baked (core/pack_collect.c): one level. */
    {.what = "placements baked",
     .body = PANELS,
     .primitive_types = BIT(PRIMITIVE_SPHERE) | BIT(PRIMITIVE_TRIANGLE) | BIT(PRIMITIVE_QUAD)},
    /* The Cornell box's blocks: boxes turned and moved by groups, no instances left, so
     * the tracer variant leaves the instance code out. */
    {.what = "the Cornell box's blocks",
     .body = GREY "quad 0 0 0  555 0 0  0 0 555 grey\n"
                  "group tall_block material grey {\n    rotate 0 1 0 15\n    translate 265 0 295\n"
                  "    box 0 0 0 165 330 165\n}\n"
                  "group short_block material grey {\n    rotate 0 1 0 -18\n    translate 130 0 65\n"
                  "    box 0 0 0 165 165 165\n}\n",
     .primitive_types = BIT(PRIMITIVE_QUAD)},
    /* A group without transforms is copied into the top level: one level. */
    {.what = "identity placement",
     .body = GREY "group material grey {\n    quad 0 0 0  1 0 0  0 1 0\n}\n",
     .primitive_types = BIT(PRIMITIVE_QUAD)},
    {.what = "a volume",
     .body = GREY "sphere 0 -10 0 1 grey\nvolume 0.5 1 1 1 {\n    sphere 0 0 0 1\n}\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE) | BIT(PRIMITIVE_INSTANCE),
     .volumes = true},
    {.what = "area lights of every kind",
     .body = LAMP "sphere 0 0 0 1 lamp\nquad 0 0 -1  1 0 0  0 1 0 lamp\ntriangle 0 0 -2  1 0 -2  0 1 -2 lamp\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE) | BIT(PRIMITIVE_QUAD) | BIT(PRIMITIVE_TRIANGLE),
     .light_types = BIT(LIGHT_SPHERE) | BIT(LIGHT_QUAD) | BIT(LIGHT_TRIANGLE),
     .emitters = true},
    /* A moving emitter emits but is no light. */
    {.what = "a moving emitter",
     .body = LAMP "moving_sphere 0 0 0  0 1 0  0.5 lamp\n",
     .primitive_types = BIT(PRIMITIVE_MOVING_SPHERE),
     .emitters = true},
    /* The summary tells what the material section holds, used or not. */
    {.what = "an unused emissive material",
     .body = LAMP GREY "sphere 0 0 0 1 grey\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE),
     .emitters = true},
    {.what = "point and sun",
     .body = GREY "sphere 0 0 0 1 grey\nlight point 0 3 0\nlight sun 0 -1 0\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE),
     .light_types = BIT(LIGHT_POINT) | BIT(LIGHT_SUN)},
    {.what = "a spot",
     .body = GREY "sphere 0 0 0 1 grey\nlight spot 0 3 0 at 0 0 0\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE),
     .light_types = BIT(LIGHT_SPOT)},
    /* The sky's image is no texture of a material. */
    {.what = "an environment",
     .body = "sky environment \"sky.hdr\"\n" GREY "sphere 0 0 0 1 grey\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE),
     .light_types = BIT(LIGHT_ENVIRONMENT)},
    {.what = "a sky box",
     .body = "sky box \"a.png\" \"b.png\" \"c.png\" \"d.png\" \"e.png\" \"f.png\"\n" GREY "sphere 0 0 0 1 grey\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE)},
    {.what = "a checker",
     .body = "texture board checker 0.5 0 0 0  1 1 1\nmaterial floor lambertian @board\nsphere 0 0 0 1 floor\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE),
     .textures = true},
    /* A normal map is an image of its material, not a texture record. */
    {.what = "a normal map",
     .body = "material bumpy lambertian 0.5 0.5 0.5 normal_map \"bumps.png\"\nsphere 0 0 0 1 bumpy\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE),
     .normal_maps = true},
    {.what = "a pbr material",
     .body = "material plastic pbr 0.8 0.2 0.1 metallic 0 roughness 0.4\nsphere 0 0 0 1 plastic\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE),
     .pbr = true},
    /* pbr with an emission is a light; a one-sided emitter too (its back sends nothing). */
    {.what = "a pbr emitter and a one-sided lamp",
     .body = "material panel pbr 0 0 0 metallic 0 roughness 1 emission 1 1 1 strength 2\n"
             "material lamp emissive 1 1 1 one_sided\n"
             "quad 0 0 0  1 0 0  0 1 0 panel\nquad 0 0 -1  1 0 0  0 1 0 lamp\n",
     .primitive_types = BIT(PRIMITIVE_QUAD),
     .light_types = BIT(LIGHT_QUAD),
     .emitters = true, .pbr = true},
    /* An alpha-masked emitter emits where it is, but is no light (its holes would be). */
    {.what = "an alpha-masked pbr emitter",
     .body = "material sign pbr 1 1 1 metallic 0 roughness 1 emission 1 1 1 alpha 0.7 alpha_cutoff 0.5\n"
             "quad 0 0 0  1 0 0  0 1 0 sign\n",
     .primitive_types = BIT(PRIMITIVE_QUAD),
     .emitters = true, .pbr = true, .alpha_mask = true},
    /* A metallic-roughness map is an image the tracer looks up: the texture code. */
    {.what = "a metallic-roughness map",
     .body = "material worn pbr 1 1 1 metallic 1 roughness 1 metallic_roughness_map \"mr.png\"\n"
             "sphere 0 0 0 1 worn\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE),
     .textures = true, .pbr = true},
    {.what = "an unused texture",
     .body = "texture spare noise 4\n" GREY "sphere 0 0 0 1 grey\n",
     .primitive_types = BIT(PRIMITIVE_SPHERE),
     .textures = true},
};

static void each_scene_is_summarised(void **state)
{
    (void)state;
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        const summary_case *c = &cases[i];
        packed_scene packed;
        pack_options options = {.keep_instances = c->keep_instances};
        pack_text(c->body, &options, &packed);
        const pack_summary *got = &packed.summary;
        if (got->primitive_types != c->primitive_types || got->light_types != c->light_types)
            fail_msg("%s: primitive types %#x, light types %#x; expected %#x, %#x", c->what, got->primitive_types,
                     got->light_types, c->primitive_types, c->light_types);
        if (got->volumes != c->volumes || got->emitters != c->emitters || got->textures != c->textures
            || got->normal_maps != c->normal_maps || got->pbr != c->pbr || got->alpha_mask != c->alpha_mask)
            fail_msg("%s: volumes %d emitters %d textures %d normal maps %d pbr %d alpha masks %d; expected %d %d %d "
                     "%d %d %d", c->what, got->volumes, got->emitters, got->textures, got->normal_maps, got->pbr,
                     got->alpha_mask, c->volumes, c->emitters, c->textures, c->normal_maps, c->pbr, c->alpha_mask);
        packed_scene_free(&packed);
    }
}

static void texel_hash_is_the_hash_of_the_texels(void **state)
{
    (void)state;
    packed_scene packed;
    pack_text("material grey lambertian 0.5 0.5 0.5\n"
              "sphere 0 0 0 1 grey\n",
              NULL, &packed);
    assert_true(packed.texel_hash == hash_bytes(HASH_START, packed.texels, (size_t)packed.texel_count * 16u));
    uint64_t first = packed.texel_hash;
    packed_scene_free(&packed);
    /* Another radius: other texels, another hash. */
    pack_text("material grey lambertian 0.5 0.5 0.5\n"
              "sphere 0 0 0 2 grey\n",
              NULL, &packed);
    assert_true(packed.texel_hash != first);
    packed_scene_free(&packed);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(each_scene_is_summarised),
        cmocka_unit_test(texel_hash_is_the_hash_of_the_texels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
