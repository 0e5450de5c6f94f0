/* scene_statements_appearance.c: the statements of how a scene looks: light, material,
 * texture (see scene_statements.h). */
#include "scene_statements.h"

#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "affine.h"

/* ------------------------------------------------------------------ names and texture references */

/* Reads the NAME of `material NAME` or `texture NAME` (kind) into name, which must be
 * new; *where gets its position, and owner ("material 'm'") what messages call it. */
static bool read_new_name(scene_parser *p, source_line *line, name_kind kind, char name[SCENE_NAME_MAX],
                          source_position *where, char owner[OWNER_BUFFER])
{
    const char *noun = kind == NAME_MATERIAL ? "material" : "texture";
    token t = {.kind = TOKEN_END};
    if (!read_definition_name(line, noun, &t, name))
        return false;
    *where = token_position(line, &t);
    if (!builder_check_new_name(&p->builder, kind, name, where))
        return false;
    snprintf(owner, OWNER_BUFFER, "%s '%s'", noun, name);
    return true;
}

/* Reads token t, written @NAME, as a reference to a texture defined earlier. */
static bool texture_from_token(scene_parser *p, const source_line *line, const token *t, int *texture)
{
    char found[FOUND_BUFFER];
    const char *text = line->text + t->offset;
    if (t->kind != TOKEN_WORD || t->length < 2 || text[0] != '@' || !is_plain_name(text + 1, t->length - 1))
        return fail_at(line, t->offset, "expected a texture reference @NAME, found %s",
                       describe_token(line, t, found, sizeof found));
    *texture = builder_find_texture(&p->builder, text + 1, t->length - 1);
    if (*texture < 0)
        return fail_at(line, t->offset, "texture %s is not defined (a texture must be defined before it is used)",
                       quote_text(found, sizeof found, text + 1, t->length - 1));
    return true;
}

/* Reads COLOR for owner: R G B (each >= 0), or @NAME of a texture defined earlier, which
 * sets *texture (else -1) and leaves out at 1 1 1, so that colour x texture = texture. */
static bool read_colour_or_texture(scene_parser *p, source_line *line, const char *owner, float out[3], int *texture)
{
    token t = {.kind = TOKEN_END};
    if (!peek_token(line, &t))
        return false;
    *texture = -1;
    if (t.kind != TOKEN_WORD || line->text[t.offset] != '@')
        return read_colour(&p->variables, line, owner, out);
    if (!next_token(line, &t) || !texture_from_token(p, line, &t, texture))
        return false;
    out[0] = out[1] = out[2] = 1;
    return true;
}

/* ------------------------------------------------------------------ lights */

/* Reads an angle in degrees for what (a cone half-angle, the sun's diameter): 0 <= angle < 90. */
static bool read_light_angle(scene_parser *p, source_line *line, const char *what, double *value, size_t *offset)
{
    if (!read_number(&p->variables, line, what, value, offset))
        return false;
    if (!(*value >= 0 && *value < 90)) {
        char number[NUMBER_BUFFER];
        return fail_at(line, *offset, "%s must be from 0 up to (not including) 90 degrees, found %s", what,
                       format_number(number, sizeof number, *value));
    }
    return true;
}

/* Reads the falloff clause of owner ("the point light"): inverse_square, or polynomial
 * C L Q (each >= 0, not all 0), into light. */
static bool read_light_falloff(scene_parser *p, source_line *line, const char *owner, scene_light *light)
{
    static const char *const terms[3] = {"constant", "linear", "quadratic"};
    token kind = {.kind = TOKEN_END};
    if (!next_token(line, &kind))
        return false;
    if (token_is(line, &kind, "inverse_square")) {
        light->falloff = FALLOFF_INVERSE_SQUARE;
        return true;
    }
    char found[FOUND_BUFFER];
    if (!token_is(line, &kind, "polynomial"))
        return fail_at(line, kind.offset, "expected a falloff for %s (inverse_square, or polynomial C L Q), found %s",
                       owner, describe_token(line, &kind, found, sizeof found));
    float attenuation[3];
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the %s term of %s's polynomial falloff", terms[i], owner);
        if (!read_non_negative_float(&p->variables, line, what, &attenuation[i]))
            return false;
    }
    /* Compared as floats: a term that rounds to 0 does not help the renderer either. */
    if (attenuation[0] == 0 && attenuation[1] == 0 && attenuation[2] == 0)
        return fail_at(line, kind.offset, "the terms of %s's polynomial falloff must not all be 0 (the light "
                       "would be infinitely bright at every distance)", owner);
    light->falloff = FALLOFF_POLYNOMIAL;
    memcpy(light->attenuation, attenuation, sizeof attenuation);
    return true;
}

/* Reads where the light of kind is: the sun's direction, or a position and, for a spot,
 * `at` and the point it shines at. owner names it ("the point light"). */
static bool read_light_placement(scene_parser *p, source_line *line, scene_light_type kind, const char *owner,
                                 scene_light *light)
{
    if (kind == SCENE_LIGHT_SUN) {
        double direction[3];
        size_t offsets[3];
        if (!read_point(&p->variables, line, "the sun's direction", direction, offsets))
            return false;
        if (!vector_normalise_to_float(direction, light->direction))
            return fail_at(line, offsets[0], "the sun's direction (0 0 0) has zero length, so it has no direction (it "
                           "is the direction the light travels, e.g. 0 -1 0 shines straight down)");
        return true;
    }
    char what[DESCRIPTION_BUFFER];
    snprintf(what, sizeof what, "%s's position", owner);
    if (!read_vector(&p->variables, line, what, light->position, NULL))
        return false;
    if (kind != SCENE_LIGHT_SPOT)
        return true;
    token at = {.kind = TOKEN_END};
    if (!next_token(line, &at))
        return false;
    char found[FOUND_BUFFER];
    if (!token_is(line, &at, "at"))
        return fail_at(line, at.offset, "expected 'at' and the point the spot light shines at after its position, "
                       "found %s", describe_token(line, &at, found, sizeof found));
    float target[3];
    size_t offsets[3];
    if (!read_vector(&p->variables, line, "the spot light's at", target, offsets))
        return false;
    double direction[3];
    for (int i = 0; i < 3; i++)
        direction[i] = (double)target[i] - light->position[i];
    if (!vector_normalise_to_float(direction, light->direction))
        return fail_at(line, offsets[0], "the spot light's at is its position (%g %g %g), so it has no direction",
                       target[0], target[1], target[2]);
    return true;
}

/* What the clauses of a light statement fill: the scene_light, and its colour and
 * intensity, which become scene_light.color once every clause is read. */
typedef struct light_clauses {
    const char *owner;               /* "the point light", for messages */
    const char *const *names;        /* the clause words this type of light takes */
    scene_light *light;
    float colour[3];
    double intensity;
    size_t intensity_offset;         /* SIZE_MAX when no intensity clause came */
} light_clauses;

/* Reads the value of clause index (into target's names) into target, a light_clauses. */
static bool read_light_clause(scene_parser *p, source_line *line, int index, void *target)
{
    light_clauses *clauses = target;
    scene_light *light = clauses->light;
    const char *owner = clauses->owner;
    /* Every type's clause words, in the order of the switch below. */
    static const char *const all_clauses[] = {"color", "intensity", "falloff", "cone", "angle", "group"};
    int clause = 0;
    while (strcmp(all_clauses[clause], clauses->names[index]) != 0)
        clause++;
    char what[DESCRIPTION_BUFFER], number[NUMBER_BUFFER], second[NUMBER_BUFFER];
    switch (clause) {
    case 0:
        snprintf(what, sizeof what, "%s's color", owner);
        return read_colour(&p->variables, line, what, clauses->colour);
    case 1:
        snprintf(what, sizeof what, "%s's intensity", owner);
        if (!read_number(&p->variables, line, what, &clauses->intensity, &clauses->intensity_offset))
            return false;
        if (!(clauses->intensity >= 0))
            return fail_at(line, clauses->intensity_offset, "%s must be >= 0, found %s", what,
                           format_number(number, sizeof number, clauses->intensity));
        return true;
    case 2:
        return read_light_falloff(p, line, owner, light);
    case 3: {
        double inner = 0, outer = 0;
        size_t inner_offset = 0, outer_offset = 0;
        if (!read_light_angle(p, line, "the spot light's inner cone angle", &inner, &inner_offset) ||
            !read_light_angle(p, line, "the spot light's outer cone angle", &outer, &outer_offset))
            return false;
        if (inner > outer)
            return fail_at(line, outer_offset, "the spot light's cone must have 0 <= inner <= outer < 90 degrees, "
                           "found inner %s and outer %s", format_number(number, sizeof number, inner),
                           format_number(second, sizeof second, outer));
        light->spot_inner_degrees = (float)inner;
        light->spot_outer_degrees = (float)outer;
        return true;
    }
    case 4: {
        double angle = 0;
        size_t offset = 0;
        if (!read_light_angle(p, line, "the sun's angle", &angle, &offset))
            return false;
        light->sun_angle_degrees = (float)angle;
        return true;
    }
    default:
        return read_light_group(p, line, owner, &light->light_group);
    }
}

/* light point X Y Z [color R G B] [intensity I] [falloff inverse_square | falloff polynomial C L Q]
 * light spot X Y Z at X Y Z [color R G B] [intensity I] [cone INNER OUTER] [falloff ...]
 * light sun DX DY DZ [color R G B] [intensity I] [angle DEGREES]
 * each with [group NAME] (its light group; default "default").
 * Only at the top level. scene_light.color is colour x intensity; the sun's direction is
 * the one its light travels. */
bool statement_light(scene_parser *p, source_line *line, const token *keyword)
{
    source_position where = token_position(line, keyword);
    if (!builder_check_light_allowed(&p->builder, &where))
        return false;
    token type = {.kind = TOKEN_END};
    if (!next_token(line, &type))
        return false;
    char found[FOUND_BUFFER];
    scene_light_type kind;
    const char *owner, *statement;
    if (token_is(line, &type, "point"))
        kind = SCENE_LIGHT_POINT, owner = "the point light", statement = "point light";
    else if (token_is(line, &type, "spot"))
        kind = SCENE_LIGHT_SPOT, owner = "the spot light", statement = "spot light";
    else if (token_is(line, &type, "sun"))
        kind = SCENE_LIGHT_SUN, owner = "the sun", statement = "sun light";
    else
        return fail_at(line, type.offset, "expected a light type (point, spot or sun), found %s",
                       describe_token(line, &type, found, sizeof found));
    scene_light light = scene_light_defaults(kind);
    if (!read_light_placement(p, line, kind, owner, &light))
        return false;

    /* The clauses each type takes. */
    static const char *const point_clauses[] = {"color", "intensity", "falloff", "group"};
    static const char *const spot_clauses[] = {"color", "intensity", "cone", "falloff", "group"};
    static const char *const sun_clauses[] = {"color", "intensity", "angle", "group"};
    light_clauses clauses = {
        .owner = owner, .light = &light, .colour = {1, 1, 1}, .intensity = 1, .intensity_offset = SIZE_MAX,
        .names = kind == SCENE_LIGHT_POINT ? point_clauses : kind == SCENE_LIGHT_SPOT ? spot_clauses : sun_clauses,
    };
    if (!read_clauses(p, line, statement, clauses.names, kind == SCENE_LIGHT_SPOT ? 5 : 4, read_light_clause,
                      &clauses))
        return false;
    char what[DESCRIPTION_BUFFER];
    snprintf(what, sizeof what, "%s's color x intensity", owner);
    /* Only a given intensity can take a (float) colour out of range. */
    size_t offset = clauses.intensity_offset != SIZE_MAX ? clauses.intensity_offset : keyword->offset;
    for (int i = 0; i < 3; i++)
        if (!to_float(line, offset, what, clauses.colour[i] * clauses.intensity, &light.color[i]))
            return false;
    return builder_add_light(&p->builder, &light);
}

/* ------------------------------------------------------------------ materials */

/* Reads specular R G B for owner (e.g. "material 'm'"): each component from 0 to 1. */
static bool read_specular(scene_parser *p, source_line *line, const char *owner, float out[3])
{
    static const char *const channels[3] = {"red", "green", "blue"};
    for (int i = 0; i < 3; i++) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the %s component of the specular colour of %s", channels[i], owner);
        if (!read_unit_float(&p->variables, line, what, &out[i]))
            return false;
    }
    return true;
}

/* What the clauses of a material fill (read_material_clauses says what each is). */
typedef struct material_clauses {
    const char *statement;           /* "metal material", for messages */
    const char *owner;               /* "material 'm'", for messages */
    const char *const *names;        /* the clause words this type of material takes */
    scene_material *material;
    double *value;                   /* fuzz or strength */
    size_t *value_offset;
} material_clauses;

/* Reads the value of clause index (into target's names) into target, a material_clauses. */
static bool read_material_clause(scene_parser *p, source_line *line, int index, void *target)
{
    const material_clauses *clauses = target;
    scene_material *material = clauses->material;
    const char *name = clauses->names[index];
    char description[DESCRIPTION_BUFFER];
    snprintf(description, sizeof description, "the %s of the %s", name, clauses->statement);
    if (strcmp(name, "normal_map") == 0) {
        if (!read_image(p, line, description, &material->normal_map))
            return false;
        /* A normal map holds vectors: the loader must not sRGB-decode it. */
        builder_mark_image_data(&p->builder, material->normal_map);
        return true;
    }
    if (strcmp(name, "phong") == 0) {
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the phong exponent of %s", clauses->owner);
        return read_positive_float(&p->variables, line, what, &material->phong_exponent);
    }
    if (strcmp(name, "group") == 0)
        return read_light_group(p, line, clauses->owner, &material->light_group);
    if (strcmp(name, "specular") == 0) {
        if (!read_specular(p, line, clauses->owner, material->specular))
            return false;
        material->specular_set = true;
        return true;
    }
    if (strcmp(name, "one_sided") == 0) {
        material->one_sided = true;
        return true;
    }
    return read_number(&p->variables, line, description, clauses->value, clauses->value_offset);
}

/* Reads the optional clauses of a material, in any order: a number (fuzz, strength) into
 * *value (offset into *value_offset), group NAME (emissive: its light group), normal_map
 * "FILE" into material->normal_map, phong
 * EXPONENT (> 0; 0 in scene_material means "the default") and specular R G B (lambertian
 * and metal) into the Whitted fields, one_sided (emissive). statement names the material
 * type for messages ("metal material"), owner the material ("material 'm'"). */
static bool read_material_clauses(scene_parser *p, source_line *line, const char *statement, const char *owner,
                                  const char *const *names, int count, scene_material *material, double *value,
                                  size_t *value_offset)
{
    material_clauses clauses = {
        .statement = statement, .owner = owner, .names = names, .material = material, .value = value,
        .value_offset = value_offset,
    };
    return read_clauses(p, line, statement, names, count, read_material_clause, &clauses);
}

/* What the clauses of a pbr material fill (read_pbr_clause says what each is). */
typedef struct pbr_clauses {
    const char *owner;               /* "material 'm'", for messages */
    scene_material *material;
    float emission[3];               /* the emission clause's colour (1 1 1 for a texture) */
    double strength;                 /* multiplies it; 1 unless given */
    size_t strength_offset;          /* where strength came, SIZE_MAX when it did not */
    bool metallic_given, roughness_given;
} pbr_clauses;

/* The clause words of a pbr material, in the order of read_pbr_clause's switch. */
static const char *const pbr_clause_names[] = {
    "metallic", "roughness", "ior",       "transmission", "emission",   "strength",
    "one_sided", "alpha",    "alpha_cutoff", "vertex_colors", "normal_map", "metallic_roughness_map",
    "group",
};
#define PBR_CLAUSE_COUNT ((int)(sizeof pbr_clause_names / sizeof pbr_clause_names[0]))

/* Reads the value of pbr clause index (into pbr_clause_names) into target, a pbr_clauses. */
static bool read_pbr_clause(scene_parser *p, source_line *line, int index, void *target)
{
    pbr_clauses *clauses = target;
    scene_material *material = clauses->material;
    char what[DESCRIPTION_BUFFER];
    snprintf(what, sizeof what, "the %s of %s", pbr_clause_names[index], clauses->owner);
    switch (index) {
    case 0:
        clauses->metallic_given = true;
        return read_unit_float(&p->variables, line, what, &material->metallic);
    case 1:
        clauses->roughness_given = true;
        return read_unit_float(&p->variables, line, what, &material->roughness);
    case 2:
        return read_positive_float(&p->variables, line, what, &material->index_of_refraction);
    case 3:
        return read_unit_float(&p->variables, line, what, &material->transmission);
    case 4:
        return read_colour_or_texture(p, line, what, clauses->emission, &material->emission_texture);
    case 5: {
        if (!read_number(&p->variables, line, what, &clauses->strength, &clauses->strength_offset))
            return false;
        char number[NUMBER_BUFFER];
        if (!(clauses->strength >= 0))
            return fail_at(line, clauses->strength_offset, "%s must be >= 0, found %s", what,
                           format_number(number, sizeof number, clauses->strength));
        return true;
    }
    case 6:
        material->one_sided = true;
        return true;
    case 7:
        material->alpha_mode = SCENE_ALPHA_MASK;
        return read_unit_float(&p->variables, line, what, &material->alpha);
    case 8:
        material->alpha_mode = SCENE_ALPHA_MASK;
        return read_unit_float(&p->variables, line, what, &material->alpha_cutoff);
    case 9:
        material->vertex_colors = true;
        return true;
    case 12:
        return read_light_group(p, line, clauses->owner, &material->light_group);
    default: {
        int *image = index == 10 ? &material->normal_map : &material->metallic_roughness_texture;
        snprintf(what, sizeof what, "the %s of the pbr material", pbr_clause_names[index]);
        if (!read_image(p, line, what, image))
            return false;
        /* Both hold values, not colours: the loader must not sRGB-decode them. */
        builder_mark_image_data(&p->builder, *image);
        return true;
    }
    }
}

/* Reads `pbr COLOR metallic M roughness R [clauses]` (type is the `pbr` token) into
 * *material for owner ("material 'm'"): glTF's metallic-roughness model
 * (docs/scene-format.md). metallic and roughness are required; ior defaults to glTF's
 * 1.5; emission is colour x strength. */
static bool read_pbr_material(scene_parser *p, source_line *line, const char *owner, const token *type,
                              scene_material *material)
{
    material->type = MATERIAL_PBR;
    material->index_of_refraction = 1.5f;
    pbr_clauses clauses = {.owner = owner, .material = material, .strength = 1, .strength_offset = SIZE_MAX};
    if (!read_colour_or_texture(p, line, owner, material->albedo, &material->albedo_texture) ||
        !read_clauses(p, line, "pbr material", pbr_clause_names, PBR_CLAUSE_COUNT, read_pbr_clause, &clauses))
        return false;
    if (!clauses.metallic_given || !clauses.roughness_given)
        return fail_at(line, type->offset, "the pbr %s needs metallic M and roughness R, each from 0 to 1 (e.g. "
                       "pbr 0.8 0.8 0.8 metallic 0 roughness 0.5)", owner);
    size_t offset = clauses.strength_offset != SIZE_MAX ? clauses.strength_offset : type->offset;
    for (int i = 0; i < 3; i++)
        if (!to_float(line, offset, "the emission (colour x strength)", clauses.emission[i] * clauses.strength,
                      &material->emission[i]))
            return false;
    return true;
}

/* Reads the material type word and everything after it into *material, for owner
 * ("material 'm'"). */
static bool read_material_type(scene_parser *p, source_line *line, const char *owner, scene_material *material)
{
    token type = {.kind = TOKEN_END};
    if (!next_token(line, &type))
        return false;
    double value = 0;
    size_t offset = type.offset;
    char number[NUMBER_BUFFER];
    char found[FOUND_BUFFER];
    static const char *const normal_map_only[] = {"normal_map"};
    if (token_is(line, &type, "lambertian")) {
        static const char *const clauses[] = {"normal_map", "phong", "specular"};
        material->type = MATERIAL_LAMBERTIAN;
        return read_colour_or_texture(p, line, owner, material->albedo, &material->albedo_texture) &&
               read_material_clauses(p, line, "lambertian material", owner, clauses, 3, material, NULL, NULL);
    }
    if (token_is(line, &type, "metal")) {
        static const char *const clauses[] = {"fuzz", "normal_map", "phong", "specular"};
        material->type = MATERIAL_METAL;
        if (!read_colour_or_texture(p, line, owner, material->albedo, &material->albedo_texture) ||
            !read_material_clauses(p, line, "metal material", owner, clauses, 4, material, &value, &offset))
            return false;
        if (!(value >= 0 && value <= 1))
            return fail_at(line, offset, "the fuzz of %s must be between 0 and 1, found %s", owner,
                           format_number(number, sizeof number, value));
        material->fuzz = (float)value;
        return true;
    }
    if (token_is(line, &type, "dielectric")) {
        material->type = MATERIAL_DIELECTRIC;
        char what[DESCRIPTION_BUFFER];
        snprintf(what, sizeof what, "the index of refraction of %s", owner);
        return read_positive_float(&p->variables, line, what, &material->index_of_refraction) &&
               read_material_clauses(p, line, "dielectric material", owner, normal_map_only, 1, material, NULL, NULL);
    }
    if (token_is(line, &type, "emissive")) {
        static const char *const clauses[] = {"strength", "one_sided", "group"};
        material->type = MATERIAL_EMISSIVE;
        float colour[3];
        value = 1;
        if (!read_colour_or_texture(p, line, owner, colour, &material->emission_texture) ||
            !read_material_clauses(p, line, "emissive material", owner, clauses, 3, material, &value, &offset))
            return false;
        if (!(value >= 0))
            return fail_at(line, offset, "the strength of %s must be >= 0, found %s", owner,
                           format_number(number, sizeof number, value));
        for (int i = 0; i < 3; i++)
            if (!to_float(line, offset, "the emission (colour x strength)", colour[i] * value, &material->emission[i]))
                return false;
        return true;
    }
    if (token_is(line, &type, "pbr"))
        return read_pbr_material(p, line, owner, &type, material);
    return fail_at(line, type.offset, "expected a material type (lambertian, metal, dielectric, emissive or pbr), "
                   "found %s", describe_token(line, &type, found, sizeof found));
}

/* material NAME lambertian COLOR [normal_map "F"] [phong E] [specular R G B] |
 * metal COLOR [fuzz F] [normal_map "F"] [phong E] [specular R G B] |
 * dielectric IOR [normal_map "F"] | emissive COLOR [strength S] [one_sided] [group NAME] |
 * pbr COLOR metallic M roughness R [ior I] [transmission T] [emission COLOR] [strength S]
 * [one_sided] [group NAME] [alpha A] [alpha_cutoff C] [vertex_colors] [normal_map "F"]
 * [metallic_roughness_map "F"], COLOR being R G B or @TEXTURE. The builder remembers where
 * NAME was defined, for duplicate errors. */
bool statement_material(scene_parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    scene_material material = scene_material_defaults();
    material.type = MATERIAL_LAMBERTIAN;
    source_position named;
    char owner[OWNER_BUFFER];
    return read_new_name(p, line, NAME_MATERIAL, material.name, &named, owner) &&
           read_material_type(p, line, owner, &material) && builder_add_material(&p->builder, &material, named);
}

/* ------------------------------------------------------------------ textures */

/* Reads one colour of a checker (which is "even" or "odd"): @TEXTURE, or R G B, which
 * becomes a hidden constant texture (empty name) defined by the checker's statement. */
static bool read_checker_colour(scene_parser *p, source_line *line, const char *owner, const char *which,
                                source_position where, int *texture)
{
    char description[DESCRIPTION_BUFFER];
    snprintf(description, sizeof description, "the %s colour of %s", which, owner);
    scene_texture constant = {.type = TEXTURE_CONSTANT, .even = -1, .odd = -1, .image = -1};
    if (!read_colour_or_texture(p, line, description, constant.color, texture))
        return false;
    return *texture >= 0 || builder_add_texture(&p->builder, &constant, where, texture);
}

/* Reads the texture type word and everything after it into *texture, for owner
 * ("texture 't'") defined at where. */
static bool read_texture_type(scene_parser *p, source_line *line, const char *owner, source_position where,
                              scene_texture *texture)
{
    token type = {.kind = TOKEN_END};
    if (!next_token(line, &type))
        return false;
    char what[DESCRIPTION_BUFFER];
    snprintf(what, sizeof what, "the scale of %s", owner);
    if (token_is(line, &type, "constant")) {
        int reference = -1;
        texture->type = TEXTURE_CONSTANT;
        if (!read_colour_or_texture(p, line, owner, texture->color, &reference))
            return false;
        if (reference >= 0) {
            /* `constant @other` is another name for the same texture. */
            scene_texture alias = builder_scene(&p->builder)->textures[reference];
            memcpy(alias.name, texture->name, sizeof alias.name);
            *texture = alias;
        }
        return true;
    }
    if (token_is(line, &type, "checker")) {
        texture->type = TEXTURE_CHECKER;
        return read_positive_float(&p->variables, line, what, &texture->scale) &&
               read_checker_colour(p, line, owner, "even", where, &texture->even) &&
               read_checker_colour(p, line, owner, "odd", where, &texture->odd);
    }
    if (token_is(line, &type, "noise") || token_is(line, &type, "turbulence") || token_is(line, &type, "marble")) {
        texture->type = token_is(line, &type, "noise") ? TEXTURE_NOISE
                        : token_is(line, &type, "turbulence") ? TEXTURE_TURBULENCE : TEXTURE_MARBLE;
        return read_positive_float(&p->variables, line, what, &texture->scale);
    }
    if (token_is(line, &type, "image")) {
        texture->type = TEXTURE_IMAGE;
        snprintf(what, sizeof what, "the image of %s", owner);
        return read_image(p, line, what, &texture->image);
    }
    char found[FOUND_BUFFER];
    return fail_at(line, type.offset, "expected a texture type (constant, checker, noise, turbulence, marble or "
                   "image), found %s", describe_token(line, &type, found, sizeof found));
}

/* texture NAME constant COLOR | checker SCALE COLOR COLOR | noise SCALE |
 * turbulence SCALE | marble SCALE | image "FILE". */
bool statement_texture(scene_parser *p, source_line *line, const token *keyword)
{
    (void)keyword;
    scene_texture texture = {.even = -1, .odd = -1, .image = -1};
    source_position where;
    char owner[OWNER_BUFFER];
    int index = -1;
    return read_new_name(p, line, NAME_TEXTURE, texture.name, &where, owner) &&
           read_texture_type(p, line, owner, where, &texture) && expect_end_of_line(line, "the texture") &&
           builder_add_texture(&p->builder, &texture, where, &index);
}
