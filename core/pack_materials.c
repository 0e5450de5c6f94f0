/* pack_materials.c: the packer's appearance sections (pack_internal.h): materials (and
 * the default grey one after the scene's), textures, image records and pixels. */
#include <string.h>

#include "pack_internal.h"

/* The MATERIAL_FLAG_* bits of m (packed_layout.h "materials"). */
static uint32_t material_flags(const scene_material *m)
{
    bool pbr = m->type == MATERIAL_PBR;
    uint32_t flags = 0;
    if (m->one_sided && (pbr || m->type == MATERIAL_EMISSIVE))
        flags |= MATERIAL_FLAG_ONE_SIDED;
    if (pbr && m->vertex_colors)
        flags |= MATERIAL_FLAG_VERTEX_COLORS;
    if (pbr && m->alpha_mode == SCENE_ALPHA_MASK)
        flags |= MATERIAL_FLAG_ALPHA_MASK;
    return flags;
}

/* The image whose alpha channel masks a pbr material: its base colour texture's, when
 * that is an image texture; PACKED_NONE otherwise (the alpha is then the factor alone). */
static uint32_t alpha_image(const scene *s, const scene_material *m)
{
    int texture = m->albedo_texture;
    if (texture < 0 || texture >= s->texture_count || s->textures[texture].type != TEXTURE_IMAGE)
        return PACKED_NONE;
    return s->textures[texture].image >= 0 ? (uint32_t)s->textures[texture].image : PACKED_NONE;
}

void pack_write_materials(packer *p)
{
    const scene *s = p->scene;
    pack_summary *summary = &p->out->summary;
    for (uint64_t i = 0; i < p->layout.material_count; i++) {
        scene_material m = scene_material_defaults();
        if (i < (uint64_t)s->material_count)
            m = s->materials[i];
        else {
            m.type = MATERIAL_LAMBERTIAN;
            m.albedo[0] = m.albedo[1] = m.albedo[2] = 0.5f;
        }
        uint32_t flags = material_flags(&m);
        bool pbr = m.type == MATERIAL_PBR;
        uint64_t base = p->layout.material_offset + i * PACKED_MATERIAL_STRIDE;
        put_texel(p->texels, base + 0, (uint32_t)m.type | flags, float_bits(m.albedo[0]), float_bits(m.albedo[1]),
                  float_bits(m.albedo[2]));
        /* texel 1 .w: the metal's fuzz, any other's light group (what an emitter's light goes to). */
        put_texel(p->texels, base + 1, float_bits(m.emission[0]), float_bits(m.emission[1]),
                  float_bits(m.emission[2]),
                  m.type == MATERIAL_METAL ? float_bits(m.fuzz) : (uint32_t)m.light_group);
        put_texel(p->texels, base + 2, float_bits(m.index_of_refraction),
                  m.albedo_texture >= 0 ? (uint32_t)m.albedo_texture : PACKED_NONE,
                  m.emission_texture >= 0 ? (uint32_t)m.emission_texture : PACKED_NONE,
                  m.normal_map >= 0 ? (uint32_t)m.normal_map : PACKED_NONE);
        /* Phong terms of the Whitted integrator: a dim white highlight on diffuse
         * surfaces and the metal's own colour on metals, unless the scene says (pbr
         * derives its own from roughness and metallic: glsl/material_phong.glsl). */
        float specular[3] = {0.04f, 0.04f, 0.04f};
        if (m.specular_set)
            memcpy(specular, m.specular, sizeof specular);
        else if (m.type == MATERIAL_METAL)
            memcpy(specular, m.albedo, sizeof specular);
        put_texel(p->texels, base + 3, float_bits(m.phong_exponent > 0 ? m.phong_exponent : 32.0f),
                  float_bits(specular[0]), float_bits(specular[1]), float_bits(specular[2]));
        if (pbr) {
            put_texel(p->texels, base + 4, float_bits(m.metallic), float_bits(m.roughness), float_bits(m.transmission),
                      m.metallic_roughness_texture >= 0 ? (uint32_t)m.metallic_roughness_texture : PACKED_NONE);
            put_texel(p->texels, base + 5, float_bits(m.alpha), float_bits(m.alpha_cutoff), alpha_image(s, &m), 0);
        }
        bool pbr_emission = pbr && (m.emission[0] > 0 || m.emission[1] > 0 || m.emission[2] > 0);
        summary->emitters |= m.type == MATERIAL_EMISSIVE || pbr_emission;
        summary->textures |= m.albedo_texture >= 0 || m.emission_texture >= 0
                             || (pbr && m.metallic_roughness_texture >= 0);
        summary->normal_maps |= m.normal_map >= 0;
        summary->material_types |= 1u << m.type;
        summary->pbr |= pbr;
        summary->alpha_mask |= (flags & MATERIAL_FLAG_ALPHA_MASK) != 0;
    }
}

void pack_write_textures(packer *p)
{
    const scene *s = p->scene;
    for (int i = 0; i < s->texture_count; i++) {
        const scene_texture *t = &s->textures[i];
        uint64_t base = p->layout.texture_offset + (uint64_t)i * PACKED_TEXTURE_STRIDE;
        put_texel(p->texels, base, (uint32_t)t->type, (uint32_t)t->even, (uint32_t)t->odd, (uint32_t)t->image);
        put_texel(p->texels, base + 1, float_bits(t->color[0]), float_bits(t->color[1]), float_bits(t->color[2]),
                  float_bits(t->scale));
        p->out->summary.textures = true;
    }
    uint64_t next_pixel = p->layout.pixel_offset;
    for (int i = 0; i < s->image_count; i++) {
        const scene_image *image = &s->images[i];
        uint32_t wrap = (uint32_t)image->wrap[0] | (uint32_t)image->wrap[1] << IMAGE_WRAP_V_SHIFT;
        put_texel(p->texels, p->layout.image_offset + (uint64_t)i * PACKED_IMAGE_STRIDE, (uint32_t)next_pixel,
                  (uint32_t)image->width, (uint32_t)image->height, wrap);
        uint64_t pixels = (uint64_t)image->width * image->height;
        if (image->pixels != NULL)
            for (uint64_t k = 0; k < 4 * pixels; k++)
                p->texels[4 * next_pixel + k] = float_bits(image->pixels[k]);
        next_pixel += pixels;
    }
}
