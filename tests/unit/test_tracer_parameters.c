/* test_tracer_parameters.c: the C struct tracer_parameter_block (core/gpu.h) and the GLSL
 * uniform block of the same name (glsl/parameters.glsl) come from one list
 * (core/tracer_interface.h) and must agree byte for byte, since core/gpu_tracer.c uploads the
 * struct as it is. Checked twice: against the std140 layout rules (no device needed),
 * and against the offsets the GL reports for the compiled tracer. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <string.h>

#include "gpu.h"

typedef struct member {
    const char *type, *name;
    size_t offset, size;
} member;

#define MEMBER_ENTRY(type, name) \
    {#type, #name, offsetof(tracer_parameter_block, name), sizeof(((tracer_parameter_block *)0)->name)},
static const member members[] = {TRACER_PARAMETERS(MEMBER_ENTRY)};
#define MEMBER_COUNT ((int)(sizeof members / sizeof members[0]))

/* The std140 base alignment and size of a GLSL scalar or vector type (GLSL 4.50, 7.6.2.2,
 * rules 1 to 3: scalars N = 4 bytes, two-component vectors 2N, three- and four-component
 * vectors 4N; a three-component vector's size is 3N). False for any other type. */
static bool std140_layout(const char *type, size_t *alignment, size_t *size)
{
    static const struct {
        const char *type;
        size_t alignment, size;
    } rules[] = {
        {"float", 4, 4},  {"int", 4, 4},    {"uint", 4, 4},   {"vec2", 8, 8},   {"ivec2", 8, 8},  {"uvec2", 8, 8},
        {"vec3", 16, 12}, {"ivec3", 16, 12}, {"uvec3", 16, 12}, {"vec4", 16, 16}, {"ivec4", 16, 16}, {"uvec4", 16, 16},
    };
    for (size_t i = 0; i < sizeof rules / sizeof rules[0]; i++)
        if (strcmp(type, rules[i].type) == 0) {
            *alignment = rules[i].alignment;
            *size = rules[i].size;
            return true;
        }
    return false;
}

static void c_struct_follows_std140_rules(void **state)
{
    (void)state;
    assert_true(MEMBER_COUNT > 20);
    size_t next = 0;
    for (int i = 0; i < MEMBER_COUNT; i++) {
        size_t alignment = 0, size = 0;
        if (!std140_layout(members[i].type, &alignment, &size))
            fail_msg("parameter %s has type %s, which core/gpu.h does not map", members[i].name, members[i].type);
        size_t expected = (next + alignment - 1) / alignment * alignment;
        if (members[i].offset != expected || members[i].size != size)
            fail_msg("parameter %s (%s): C offset %zu size %zu, std140 offset %zu size %zu", members[i].name,
                     members[i].type, members[i].offset, members[i].size, expected, size);
        next = expected + size;
    }
    /* Nothing but the list in the struct: its end is the last member's, rounded to 16. */
    assert_int_equal(sizeof(tracer_parameter_block), (next + 15) / 16 * 16);
}

static void a_vec3_leaves_room_for_a_scalar(void **state)
{
    (void)state;
    /* std140 puts a scalar right after a vec3 (offset 12 of its 16): the C mapping must
     * too, or every later member would be off by 4. */
    assert_int_equal(offsetof(tracer_parameter_block, lens_radius),
                     offsetof(tracer_parameter_block, camera_origin) + 12);
}

static void gl_offsets_match_the_c_struct(void **state)
{
    (void)state;
    gpu_context *context = NULL;
    rt_error error;
    if (gpu_create(NULL, &context, &error) != RT_OK)
        fail_msg("%s", error.message);
    const char *names[MEMBER_COUNT];
    int offsets[MEMBER_COUNT];
    for (int i = 0; i < MEMBER_COUNT; i++)
        names[i] = members[i].name;
    int block_size = 0;
    rt_status status = gpu_tracer_parameter_layout(context, MEMBER_COUNT, names, offsets, &block_size, &error);
    gpu_destroy(context);
    if (status != RT_OK)
        fail_msg("%s", error.message);
    for (int i = 0; i < MEMBER_COUNT; i++)
        if (offsets[i] != (int)members[i].offset)
            fail_msg("parameter %s: the GL puts it at %d, the C struct at %zu", members[i].name, offsets[i],
                     members[i].offset);
    assert_true(block_size > 0);
    assert_true((size_t)block_size <= sizeof(tracer_parameter_block));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(c_struct_follows_std140_rules),
        cmocka_unit_test(a_vec3_leaves_room_for_a_scalar),
        cmocka_unit_test(gl_offsets_match_the_c_struct),
    };
    return cmocka_run_group_tests_name("tracer parameter block", tests, NULL, NULL);
}
