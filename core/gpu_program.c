/* gpu_program.c: GLSL programs from the module table of core/shader_sources.S (gpu_internal.h
 * gpu_build_program): the fragment program's modules joined after the variant's
 * #defines (gpu_variant_defines), compiler messages that name the module and its line,
 * and GL's errors as rt_error. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "gpu_internal.h"
#include "shader_sources.h"

rt_status gpu_check_gl(const char *step, rt_error *error)
{
    GLenum code = glGetError();
    if (code == GL_NO_ERROR)
        return RT_OK;
    while (glGetError() != GL_NO_ERROR) {
    }
    const char *name = code == GL_OUT_OF_MEMORY ? "GL_OUT_OF_MEMORY"
                       : code == GL_INVALID_VALUE ? "GL_INVALID_VALUE"
                       : code == GL_INVALID_OPERATION ? "GL_INVALID_OPERATION"
                       : code == GL_INVALID_ENUM ? "GL_INVALID_ENUM"
                       : code == GL_INVALID_FRAMEBUFFER_OPERATION ? "GL_INVALID_FRAMEBUFFER_OPERATION"
                                                                   : "GL error";
    return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: %s failed (%s, 0x%04x)", step, name, code);
}

/* True when the length characters at line say "error", in any case. */
static bool says_error(const char *line, size_t length)
{
    for (size_t i = 0; i + 5 <= length; i++)
        if (strncasecmp(line + i, "error", 5) == 0)
            return true;
    return false;
}

/* Removes from log (a compiler's or linker's, one message a line) every line that does
 * not say "error", when some line does: Mesa puts a warning before the errors for every
 * global the tracer reads before it writes, and those alone would fill the message
 * (rt_error's 1,024 bytes) before the error that failed the build. */
static void keep_error_lines(char *log)
{
    bool any_error = false;
    for (const char *line = log; *line != '\0' && !any_error;) {
        size_t length = strcspn(line, "\n");
        any_error = says_error(line, length);
        line += length + (line[length] == '\n');
    }
    if (!any_error)
        return;
    char *kept = log;
    for (const char *line = log; *line != '\0';) {
        size_t length = strcspn(line, "\n"), whole = length + (line[length] == '\n');
        if (says_error(line, length)) {
            memmove(kept, line, whole);
            kept += whole;
        }
        line += whole;
    }
    *kept = '\0';
}

/* True when a shader compiled (program false) or a program linked (program true);
 * otherwise deletes it and sets error to "GPU: WHAT: " and its info log, error lines
 * only when it has any (keep_error_lines). */
static bool gl_object_built(GLuint object, bool program, const char *what, rt_error *error)
{
    GLint ok = 0, length = 0;
    if (program) {
        glGetProgramiv(object, GL_LINK_STATUS, &ok);
        glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
    } else {
        glGetShaderiv(object, GL_COMPILE_STATUS, &ok);
        glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
    }
    if (ok)
        return true;
    char *log = length > 0 ? malloc((size_t)length + 1) : NULL;
    if (log != NULL) {
        log[0] = '\0';
        if (program)
            glGetProgramInfoLog(object, length + 1, NULL, log);
        else
            glGetShaderInfoLog(object, length + 1, NULL, log);
        keep_error_lines(log);
    }
    if (program)
        glDeleteProgram(object);
    else
        glDeleteShader(object);
    rt_error_set(error, RT_ERROR_RUNTIME, "GPU: %s: %s", what, log != NULL ? log : "");
    free(log);
    return false;
}

/* Compiles one shader stage from the given source parts. Returns the shader, or 0 with
 * the compiler's log in error. */
static GLuint compile_stage(GLenum stage, const char *const *parts, int part_count, rt_error *error)
{
    GLuint shader = glCreateShader(stage);
    glShaderSource(shader, part_count, parts, NULL);
    glCompileShader(shader);
    const char *what = stage == GL_VERTEX_SHADER ? "the vertex shader does not compile"
                                                 : "the fragment shader does not compile";
    return gl_object_built(shader, false, what, error) ? shader : 0;
}

/* Links a vertex and a fragment shader into a program. Returns the program, or 0 with
 * the linker's log in error. The shaders are deleted either way. */
static GLuint link_program(GLuint vertex, GLuint fragment, rt_error *error)
{
    GLuint program = glCreateProgram();
    glAttachShader(program, vertex);
    glAttachShader(program, fragment);
    glLinkProgram(program);
    glDeleteShader(vertex);
    glDeleteShader(fragment);
    return gl_object_built(program, true, "a shader program does not link", error) ? program : 0;
}

/* The most modules a fragment program may have (shader_sources.S's table). */
#define GPU_MAX_SHADER_MODULES 48
/* Module i's lines are numbered from (i + 1) * GPU_MODULE_LINES + 1 (a #line before it), so
 * that a compiler message's line says which module it is in: Mesa's messages do not
 * carry the source string number of #line. No module is that long. */
#define GPU_MODULE_LINES 10000

/* Rewrites the compiler log in error (after "compile: ") so that each message's
 * "SOURCE:LINE(" names the module and its own line ("glsl/sky.glsl:8("). */
static void name_modules_in_log(rt_error *error)
{
    char *log = strstr(error->message, "compile: ");
    if (log == NULL)
        return;
    log += strlen("compile: ");
    char named[sizeof error->message];
    size_t used = 0;
    for (const char *line = log; *line != '\0' && used + 1 < sizeof named;) {
        const char *end = strchr(line, '\n');
        size_t length = end ? (size_t)(end - line) + 1 : strlen(line);
        int source = 0, number = 0, consumed = 0;
        int module = -1;
        if (sscanf(line, "%d:%d(%n", &source, &number, &consumed) == 2 && consumed > 0)
            module = source > 0 ? source - 1 : number / GPU_MODULE_LINES - 1;
        for (int i = 0; module >= 0 && shader_modules[i].path != NULL; i++)
            if (i == module) {
                used += (size_t)snprintf(named + used, sizeof named - used, "%s:%d(%.*s", shader_modules[i].path,
                                         number % GPU_MODULE_LINES, (int)(length - (size_t)consumed),
                                         line + consumed);
                module = -2;
            }
        if (module != -2)
            used += (size_t)snprintf(named + used, sizeof named - used, "%.*s", (int)length, line);
        line += length;
    }
    snprintf(log, sizeof error->message - (size_t)(log - error->message), "%s", named);
}

/* Compiles a fragment shader: "#version 450 core" + defines + every module of the table of
 * core/shader_sources.S whose programs include program (a SHADER_PROGRAM_* bit), in the
 * table's order, each after a #line that numbers it by its place in the table. Returns
 * the shader or 0 with error set, its messages naming the modules. */
static GLuint compile_fragment_program(uintptr_t program, const char *defines, rt_error *error)
{
    const char *parts[3 + 2 * GPU_MAX_SHADER_MODULES];
    char line_directives[GPU_MAX_SHADER_MODULES][32];
    int count = 0;
    parts[count++] = "#version 450 core\n";
    parts[count++] = defines;
    /* RTSPHERES_TEST_SHADER_LINE: a line of GLSL put before the first module, for the test
     * that a shader that does not compile is a message naming its error
     * (tests/render/test-tracer-variants.sh). */
    const char *test_line = getenv("RTSPHERES_TEST_SHADER_LINE");
    char test_part[256];
    if (test_line != NULL) {
        snprintf(test_part, sizeof test_part, "%s\n", test_line);
        parts[count++] = test_part;
    }
    for (int i = 0; shader_modules[i].path != NULL; i++) {
        if (i == GPU_MAX_SHADER_MODULES) {
            rt_error_set(error, RT_ERROR_RUNTIME, "GPU: core/shader_sources.S lists more than %d shader modules "
                         "(GPU_MAX_SHADER_MODULES in core/gpu_program.c)", GPU_MAX_SHADER_MODULES);
            return 0;
        }
        if ((shader_modules[i].programs & program) == 0)
            continue;
        snprintf(line_directives[i], sizeof line_directives[i], "#line %d %d\n", (i + 1) * GPU_MODULE_LINES + 1,
                 i + 1);
        parts[count++] = line_directives[i];
        parts[count++] = shader_modules[i].source;
    }
    GLuint shader = compile_stage(GL_FRAGMENT_SHADER, parts, count, error);
    if (shader == 0)
        name_modules_in_log(error);
    return shader;
}

GLuint gpu_build_program(const char *vertex_source, uintptr_t program, const char *defines, rt_error *error)
{
    const char *vertex_parts[] = {"#version 450 core\n", defines, vertex_source};
    GLuint vertex = compile_stage(GL_VERTEX_SHADER, vertex_parts, 3, error);
    if (vertex == 0)
        return 0;
    GLuint fragment = compile_fragment_program(program, defines, error);
    if (fragment == 0) {
        glDeleteShader(vertex);
        return 0;
    }
    return link_program(vertex, fragment, error);
}

/* The light group layers the variant holds in registers through a pass
 * (TRACER_LIGHT_GROUP_REGISTERS_MAX of core/tracer_interface.h; glsl/light_groups.glsl):
 * all of them when there are that few, else none (settings NULL: none). The environment's
 * RTSPHERES_TEST_LIGHT_GROUP_IMAGE=1 makes it none, so that a test can hold the two ways'
 * layers against each other (tests/render/test-light-groups.sh). */
static uint32_t light_group_registers(uint32_t omitted, const tracer_parameter_block *settings)
{
    if (settings == NULL || (omitted & GPU_OMIT_LIGHT_GROUPS)
        || settings->light_group_count > TRACER_LIGHT_GROUP_REGISTERS_MAX)
        return 0;
    const char *image_way = getenv("RTSPHERES_TEST_LIGHT_GROUP_IMAGE");
    return image_way != NULL && strcmp(image_way, "1") == 0 ? 0 : settings->light_group_count;
}

void gpu_variant_defines(uint32_t omitted, const tracer_parameter_block *settings, char *defines, size_t size)
{
    static const struct {
        uint32_t bit;
        const char *name;
    } features[] = {
        {GPU_OMIT_DIRECT_LIGHT, "RTSPHERES_OMIT_DIRECT_LIGHT"},
        {GPU_OMIT_VOLUMES, "RTSPHERES_OMIT_VOLUMES"},
        {GPU_OMIT_TEXTURES, "RTSPHERES_OMIT_TEXTURES"},
        {GPU_OMIT_SPHERES, "RTSPHERES_OMIT_SPHERES"},
        {GPU_OMIT_MOVING_SPHERES, "RTSPHERES_OMIT_MOVING_SPHERES"},
        {GPU_OMIT_TRIANGLES, "RTSPHERES_OMIT_TRIANGLES"},
        {GPU_OMIT_INSTANCES, "RTSPHERES_OMIT_INSTANCES"},
        {GPU_OMIT_EMITTERS, "RTSPHERES_OMIT_EMITTERS"},
        {GPU_OMIT_QUADS, "RTSPHERES_OMIT_QUADS"},
        {GPU_OMIT_PBR, "RTSPHERES_OMIT_PBR"},
        {GPU_OMIT_ALPHA_MASK, "RTSPHERES_OMIT_ALPHA_MASK"},
        {GPU_OMIT_VERTEX_COLORS, "RTSPHERES_OMIT_VERTEX_COLORS"},
        {GPU_FIX_UNIFORMS, "RTSPHERES_FIX_UNIFORMS"},
        {GPU_OMIT_LIGHT_CHOICE, "RTSPHERES_OMIT_LIGHT_CHOICE"},
        {GPU_OMIT_RECTANGLE_LIGHTS, "RTSPHERES_OMIT_RECTANGLE_LIGHTS"},
        {GPU_OMIT_LIGHT_GROUPS, "RTSPHERES_OMIT_LIGHT_GROUPS"},
        {GPU_OMIT_SPHERE_LIGHTS, "RTSPHERES_OMIT_SPHERE_LIGHTS"},
        {GPU_OMIT_TRIANGLE_LIGHTS, "RTSPHERES_OMIT_TRIANGLE_LIGHTS"},
        {GPU_OMIT_DELTA_LIGHTS, "RTSPHERES_OMIT_DELTA_LIGHTS"},
        {GPU_OMIT_ENVIRONMENT_LIGHT, "RTSPHERES_OMIT_ENVIRONMENT_LIGHT"},
        {GPU_OMIT_MANY_LIGHTS, "RTSPHERES_OMIT_MANY_LIGHTS"},
        {GPU_OMIT_LAMBERTIAN, "RTSPHERES_OMIT_LAMBERTIAN"},
        {GPU_OMIT_METAL, "RTSPHERES_OMIT_METAL"},
        {GPU_OMIT_DIELECTRIC, "RTSPHERES_OMIT_DIELECTRIC"},
        {GPU_OMIT_LIGHT_TREE, "RTSPHERES_OMIT_LIGHT_TREE"},
        {GPU_OMIT_DIRECT_EMISSION, "RTSPHERES_OMIT_DIRECT_EMISSION"},
        {GPU_OMIT_SQUARES, "RTSPHERES_OMIT_SQUARES"},
        {GPU_OMIT_STACK_WALK, "RTSPHERES_OMIT_STACK_WALK"},
    };
    bool fixed = (omitted & GPU_FIX_UNIFORMS) != 0;
    size_t used = 0;
    defines[0] = '\0';
    for (size_t i = 0; i < sizeof features / sizeof features[0] && used < size; i++)
        used += (size_t)snprintf(defines + used, size - used, "#define %s %d\n", features[i].name,
                                 (omitted & features[i].bit) != 0);
    if (used < size)
        used += (size_t)snprintf(
            defines + used, size - used,
            "#define RTSPHERES_INTEGRATOR %d\n#define RTSPHERES_SKY_TYPE %d\n#define RTSPHERES_SAMPLER %d\n",
            fixed ? settings->integrator : 0, fixed ? settings->sky_type : 0, fixed ? settings->sampler : 0);
    if (used < size)
        snprintf(defines + used, size - used, "#define RTSPHERES_LIGHT_GROUP_REGISTERS %u\n",
                 light_group_registers(omitted, settings));
}

_Static_assert(GPU_OMIT_STACK_WALK << 1 == 1u << GPU_VARIANT_BITS, "GPU_VARIANT_BITS must cover every GPU_OMIT_* bit");

uint64_t gpu_variant_key(uint32_t omitted, const tracer_parameter_block *settings)
{
    uint64_t key = omitted & ((1u << GPU_VARIANT_BITS) - 1u);
    key |= (uint64_t)light_group_registers(omitted, settings) << 44;
    if (omitted & GPU_FIX_UNIFORMS)
        return key | (uint64_t)(settings->integrator & 3) << 32 | (uint64_t)(settings->sky_type & 15) << 36
               | (uint64_t)(settings->sampler & 3) << 40;
    return key;
}
