/* gpu.c: EGL context and the GLSL tracer; the only file that calls egl* and gl*.
 * See gpu.h for the order of set-up and how failures are told apart. */
#include "gpu.h"

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hash.h"
#include "scene.h"
#include "shader_sources.h"

/* Tracer variants kept per context: a render uses one (and the AOV pass one more); an
 * animation or sweep keeps using the same few. */
#define GPU_PROGRAM_CACHE_SIZE 16

struct gpu_context {
    EGLDisplay display;
    EGLContext context;
    gpu_info info;
    gpu_options options;
    /* Kept between renders on this context (frames of an animation, a sweep): the
     * compiled tracer, and the last packed scene uploaded with its hash. */
    struct {                              /* compiled tracer variants, by variant key */
        uint32_t key;
        GLuint program;
    } tracer_programs[GPU_PROGRAM_CACHE_SIZE];
    int tracer_program_count;
    int next_eviction;                    /* the slot a full cache replaces next */
    GLuint packed_texture;                /* a buffer texture over packed_buffer */
    GLuint packed_buffer;
    uint64_t packed_hash;
    uint32_t packed_texel_count;
};

struct gpu_tracer {
    gpu_context *context;
    int width, height;
    GLuint program;
    GLuint vertex_array;
    GLuint packed_texture;
    GLuint packed_buffer;
    GLuint state_textures[2][TRACER_STATE_COUNT];
    GLuint framebuffers[2];
    GLuint counter_buffer;
    GLuint parameter_buffer;     /* the parameter block (tracer_parameter_block) */
    int current;                 /* which state set holds the latest pass */
    gpu_tracer_parameters parameters;   /* as created, for the AOV pass */
    bool reused_scene;           /* the packed scene was already on the device */
};

gpu_options gpu_options_defaults(void)
{
    return (gpu_options){0};
}

/* Returns a readable name for an EGL error code. */
static const char *egl_error_name(EGLint code)
{
    switch (code) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    default: return "EGL error";
    }
}

/* True when the space-separated list contains name as a whole word. */
static bool has_extension(const char *list, const char *name)
{
    if (list == NULL)
        return false;
    size_t length = strlen(name);
    for (const char *p = list; (p = strstr(p, name)) != NULL; p += length)
        if ((p == list || p[-1] == ' ') && (p[length] == ' ' || p[length] == '\0'))
            return true;
    return false;
}

static void copy_string(char *destination, size_t size, const char *source)
{
    snprintf(destination, size, "%s", source ? source : "");
}

/* Device query names newer than some epoxy headers (values from Khronos' eglext.h). */
#ifndef EGL_DRM_RENDER_NODE_FILE_EXT
#define EGL_DRM_RENDER_NODE_FILE_EXT 0x3377
#endif
#ifndef EGL_DRIVER_NAME_EXT
#define EGL_DRIVER_NAME_EXT 0x335E
#endif
#ifndef EGL_RENDERER_EXT
#define EGL_RENDERER_EXT 0x335F
#endif

/* Fills out with what EGL tells about device: its extensions, and each string that one of
 * them says can be queried (nothing is asked that the device does not offer). */
static void describe_device(EGLDeviceEXT device, gpu_device_description *out)
{
    memset(out, 0, sizeof *out);
    const char *extensions = eglQueryDeviceStringEXT(device, EGL_EXTENSIONS);
    copy_string(out->extensions, sizeof out->extensions, extensions);
    out->software = has_extension(extensions, "EGL_MESA_device_software");
    if (has_extension(extensions, "EGL_EXT_device_drm"))
        copy_string(out->drm_device_file, sizeof out->drm_device_file,
                    eglQueryDeviceStringEXT(device, EGL_DRM_DEVICE_FILE_EXT));
    if (has_extension(extensions, "EGL_EXT_device_drm_render_node"))
        copy_string(out->drm_render_node, sizeof out->drm_render_node,
                    eglQueryDeviceStringEXT(device, EGL_DRM_RENDER_NODE_FILE_EXT));
    if (has_extension(extensions, "EGL_EXT_device_query_name")) {
        copy_string(out->vendor, sizeof out->vendor, eglQueryDeviceStringEXT(device, EGL_VENDOR));
        copy_string(out->renderer, sizeof out->renderer, eglQueryDeviceStringEXT(device, EGL_RENDERER_EXT));
    }
    if (has_extension(extensions, "EGL_EXT_device_persistent_id"))
        copy_string(out->driver, sizeof out->driver, eglQueryDeviceStringEXT(device, EGL_DRIVER_NAME_EXT));
    /* A failed query of a string the device claims leaves only an EGL error behind. */
    eglGetError();
}

static void GLAPIENTRY debug_message_callback(GLenum source, GLenum type, GLuint id, GLenum severity,
                                              GLsizei length, const GLchar *message, const void *user)
{
    (void)source; (void)type; (void)id; (void)severity; (void)length;
    const gpu_context *context = user;
    if (context->options.log != NULL) {
        char line[1200];
        snprintf(line, sizeof line, "GL: %s", message);
        context->options.log(context->options.log_context, line);
    }
}

/* Appends one failed attempt's message to the list of what was tried ("; " between),
 * cutting it short when the buffer is full. */
static void append_attempt(char *tried, size_t size, const char *message)
{
    size_t used = strlen(tried);
    if (used > 0 && used + 2 < size) {
        memcpy(tried + used, "; ", 3);
        used += 2;
    }
    for (; *message != '\0' && used + 1 < size; used++)
        tried[used] = *message++;
    tried[used] = '\0';
}

/* Initialises display and creates + binds a GL 4.5 core context on it. Returns RT_OK or
 * RT_ERROR_RUNTIME naming the failing call (the display is terminated on failure). */
static rt_status create_context_on(gpu_context *context, EGLDisplay display, const char *what, rt_error *error)
{
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor))
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: EGL driver failure: eglInitialize on %s failed (%s)",
                            what, egl_error_name(eglGetError()));
    const char *display_extensions = eglQueryString(display, EGL_EXTENSIONS);
    if (!has_extension(display_extensions, "EGL_KHR_surfaceless_context")) {
        eglTerminate(display);
        return rt_error_set(error, RT_ERROR_RUNTIME,
                            "GPU: %s has no EGL_KHR_surfaceless_context; cannot render without a window", what);
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        eglTerminate(display);
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: %s does not offer desktop OpenGL (%s)", what,
                            egl_error_name(eglGetError()));
    }
    EGLConfig config = EGL_NO_CONFIG_KHR;
    if (!has_extension(display_extensions, "EGL_KHR_no_config_context")) {
        EGLint count = 0;
        const EGLint wanted[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        if (!eglChooseConfig(display, wanted, &config, 1, &count) || count < 1) {
            eglTerminate(display);
            return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: %s has no OpenGL config", what);
        }
    }
    const EGLint attributes[] = {
        EGL_CONTEXT_MAJOR_VERSION, 4,
        EGL_CONTEXT_MINOR_VERSION, 5,
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
        EGL_CONTEXT_OPENGL_DEBUG, context->options.debug_output ? EGL_TRUE : EGL_FALSE,
        EGL_NONE,
    };
    EGLContext gl_context = eglCreateContext(display, config, EGL_NO_CONTEXT, attributes);
    if (gl_context == EGL_NO_CONTEXT) {
        EGLint code = eglGetError();
        eglTerminate(display);
        return rt_error_set(error, RT_ERROR_RUNTIME,
                            "GPU: %s cannot create an OpenGL 4.5 core context (%s)", what, egl_error_name(code));
    }
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, gl_context)) {
        EGLint code = eglGetError();
        eglDestroyContext(display, gl_context);
        eglTerminate(display);
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: eglMakeCurrent on %s failed (%s)", what,
                            egl_error_name(code));
    }
    context->display = display;
    context->context = gl_context;
    copy_string(context->info.egl_vendor, sizeof context->info.egl_vendor, eglQueryString(display, EGL_VENDOR));
    copy_string(context->info.egl_version, sizeof context->info.egl_version, eglQueryString(display, EGL_VERSION));
    return RT_OK;
}

/* Fills info's work bound from the renderer (gpu.h). llvmpipe names its vector width,
 * "llvmpipe (LLVM 15.0.6, 256 bits)": a lane is 32 bits. Any other software renderer,
 * or a width that cannot be read, is taken to run 16 lanes (512 bits), the widest
 * llvmpipe uses. */
static void set_work_limits(gpu_info *info)
{
    enum { LOOP_ITERATION_CAP = 65535, OVERSHOOT = 1024, HARDWARE_WORK_CAP = 1000000, HARDWARE_MAX_BUDGET = 50000 };
    info->simd_lanes = 0;
    if (info->software) {
        info->simd_lanes = 16;
        const char *bits = strstr(info->gl_renderer, " bits)");
        if (bits != NULL) {
            const char *start = bits;
            while (start > info->gl_renderer && start[-1] >= '0' && start[-1] <= '9')
                start--;
            int width = atoi(start);
            if (width >= 128 && width <= 512 && width % 32 == 0)
                info->simd_lanes = width / 32;
        }
    }
    if (info->simd_lanes == 0) {
        info->work_cap = HARDWARE_WORK_CAP;
        info->max_pass_work_budget = HARDWARE_MAX_BUDGET;
    } else {
        info->work_cap = LOOP_ITERATION_CAP / (info->simd_lanes + 1) - OVERSHOOT;
        info->max_pass_work_budget = info->work_cap / 2;
    }
}

/* Reads renderer strings and limits of the current context into context->info. */
static void read_gl_info(gpu_context *context)
{
    gpu_info *info = &context->info;
    copy_string(info->gl_vendor, sizeof info->gl_vendor, (const char *)glGetString(GL_VENDOR));
    copy_string(info->gl_renderer, sizeof info->gl_renderer, (const char *)glGetString(GL_RENDERER));
    copy_string(info->gl_version, sizeof info->gl_version, (const char *)glGetString(GL_VERSION));
    copy_string(info->glsl_version, sizeof info->glsl_version,
                (const char *)glGetString(GL_SHADING_LANGUAGE_VERSION));
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &info->max_texture_size);
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &info->max_texture_buffer_size);
    /* For tests of the "scene too large" path, which no real test scene could reach
     * (134M texels is 2 GiB): RTSPHERES_TEST_MAX_TEXTURE_BUFFER_SIZE lowers, never
     * raises, the limit. */
    const char *test_limit = getenv("RTSPHERES_TEST_MAX_TEXTURE_BUFFER_SIZE");
    if (test_limit != NULL && atoi(test_limit) > 0 && atoi(test_limit) < info->max_texture_buffer_size)
        info->max_texture_buffer_size = atoi(test_limit);
    glGetIntegerv(GL_MAX_DRAW_BUFFERS, &info->max_draw_buffers);
    glGetIntegerv(GL_MAX_COLOR_ATTACHMENTS, &info->max_color_attachments);
    glGetIntegerv(GL_MAX_FRAGMENT_ATOMIC_COUNTERS, &info->max_fragment_atomic_counters);
    info->software = strstr(info->gl_renderer, "llvmpipe") != NULL || strstr(info->gl_renderer, "softpipe") != NULL
                     || strstr(info->gl_renderer, "swrast") != NULL;
    set_work_limits(info);
}

rt_status gpu_create(const gpu_options *options, gpu_context **out, rt_error *error)
{
    *out = NULL;
    gpu_context *context = calloc(1, sizeof *context);
    if (context == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory");
    context->options = options ? *options : gpu_options_defaults();
    context->info.device_index = -1;

    const char *client_extensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    bool platform_base = has_extension(client_extensions, "EGL_EXT_platform_base");
    bool platform_device = platform_base && has_extension(client_extensions, "EGL_EXT_platform_device")
                           && has_extension(client_extensions, "EGL_EXT_device_enumeration");
    bool platform_surfaceless = platform_base && has_extension(client_extensions, "EGL_MESA_platform_surfaceless");

    rt_status status = RT_ERROR_NO_DEVICE;
    rt_error attempt = {{0}};
    char tried[1024] = "";

    EGLDeviceEXT devices[GPU_MAX_DEVICES];
    EGLint device_count = 0;
    if (platform_device && !eglQueryDevicesEXT(GPU_MAX_DEVICES, devices, &device_count))
        device_count = 0;
    if (device_count < 0 || device_count > GPU_MAX_DEVICES)
        device_count = 0;
    context->info.device_count = device_count;
    for (int index = 0; index < device_count; index++)
        describe_device(devices[index], &context->info.devices[index]);

    if (context->options.device > 0) {
        /* options.device is N + 1 for --device N (0 means "choose"). */
        int index = context->options.device - 1;
        if (index >= device_count) {
            free(context);
            if (device_count == 0)
                return rt_error_set(error, RT_ERROR_INPUT, "GPU: --device %d asked for, but there are no EGL devices "
                                    "(%s)", index, platform_surfaceless
                                        ? "leave --device out to use Mesa's surfaceless platform"
                                        : "no driver offers EGL_EXT_platform_device");
            if (device_count == 1)
                return rt_error_set(error, RT_ERROR_INPUT, "GPU: --device %d asked for, but there is 1 EGL device "
                                    "(device 0; `rtspheres info` lists it)", index);
            return rt_error_set(error, RT_ERROR_INPUT, "GPU: --device %d asked for, but there are %d EGL devices "
                                "(devices 0 to %d; `rtspheres info` lists them)", index, (int)device_count,
                                (int)device_count - 1);
        }
        EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[index], NULL);
        char what[64];
        snprintf(what, sizeof what, "EGL device %d", index);
        status = display == EGL_NO_DISPLAY
                     ? rt_error_set(&attempt, RT_ERROR_RUNTIME, "GPU: no display for %s", what)
                     : create_context_on(context, display, what, &attempt);
        if (status == RT_OK) {
            context->info.device_index = index;
            copy_string(context->info.platform, sizeof context->info.platform, "device");
            copy_string(context->info.device_extensions, sizeof context->info.device_extensions,
                        context->info.devices[index].extensions);
        }
    } else {
        /* Hardware devices first: a device without EGL_MESA_device_software is a real GPU. */
        for (int pass = 0; pass < 2 && status != RT_OK; pass++) {
            for (int index = 0; index < device_count && status != RT_OK; index++) {
                const char *device_extensions = context->info.devices[index].extensions;
                bool software = context->info.devices[index].software;
                if (software != (pass == 1))
                    continue;
                /* Mesa's software device is the same llvmpipe as the surfaceless platform;
                 * prefer the latter, which is what every Mesa install has been tested with. */
                if (software && platform_surfaceless)
                    continue;
                EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, devices[index], NULL);
                if (display == EGL_NO_DISPLAY)
                    continue;
                char what[64];
                snprintf(what, sizeof what, "EGL device %d", index);
                status = create_context_on(context, display, what, &attempt);
                if (status == RT_OK) {
                    context->info.device_index = index;
                    copy_string(context->info.platform, sizeof context->info.platform, "device");
                    copy_string(context->info.device_extensions, sizeof context->info.device_extensions,
                                device_extensions);
                } else {
                    append_attempt(tried, sizeof tried, attempt.message);
                }
            }
        }
        if (status != RT_OK && platform_surfaceless) {
            EGLDisplay display = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
            if (display != EGL_NO_DISPLAY) {
                status = create_context_on(context, display, "the Mesa surfaceless platform", &attempt);
                if (status == RT_OK)
                    copy_string(context->info.platform, sizeof context->info.platform, "surfaceless");
                else
                    append_attempt(tried, sizeof tried, attempt.message);
            }
        }
    }

    if (status != RT_OK) {
        free(context);
        if (tried[0] != '\0')
            return rt_error_set(error, RT_ERROR_RUNTIME, "%s", tried);
        if (attempt.message[0] != '\0')
            return rt_error_set(error, status, "%s", attempt.message);
        return rt_error_set(error, RT_ERROR_NO_DEVICE,
                            "GPU: no usable EGL device: no GPU driver offers EGL_EXT_platform_device and Mesa's "
                            "surfaceless platform is missing. Install Mesa (apt-get install libegl-mesa0 "
                            "libgl1-mesa-dri) or your GPU vendor's EGL driver");
    }

    read_gl_info(context);
    if (context->options.debug_output && epoxy_has_gl_extension("GL_KHR_debug")) {
        glEnable(GL_DEBUG_OUTPUT);
        glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
        glDebugMessageCallback(debug_message_callback, context);
    }
    *out = context;
    return RT_OK;
}

void gpu_destroy(gpu_context *context)
{
    if (context == NULL)
        return;
    for (int i = 0; i < context->tracer_program_count; i++)
        if (context->tracer_programs[i].program)
            glDeleteProgram(context->tracer_programs[i].program);
    if (context->packed_texture)
        glDeleteTextures(1, &context->packed_texture);
    if (context->packed_buffer)
        glDeleteBuffers(1, &context->packed_buffer);
    eglMakeCurrent(context->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(context->display, context->context);
    eglTerminate(context->display);
    free(context);
}

void gpu_get_info(const gpu_context *context, gpu_info *info)
{
    *info = context->info;
}

/* ---- tracer ------------------------------------------------------------------------- */

/* Checks glGetError and turns any error into RT_ERROR_RUNTIME naming the step. */
static rt_status check_gl(const char *step, rt_error *error)
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

/* Compiles one shader stage from the given source parts. Returns the shader, or 0 with
 * the compiler's log in error. */
static GLuint compile_stage(GLenum stage, const char *const *parts, int part_count, rt_error *error)
{
    GLuint shader = glCreateShader(stage);
    glShaderSource(shader, part_count, parts, NULL);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[800];
        glGetShaderInfoLog(shader, sizeof log, NULL, log);
        rt_error_set(error, RT_ERROR_RUNTIME, "GPU: the %s shader does not compile: %s",
                     stage == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
        glDeleteShader(shader);
        return 0;
    }
    return shader;
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
    GLint ok = 0;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[800];
        glGetProgramInfoLog(program, sizeof log, NULL, log);
        glDeleteProgram(program);
        rt_error_set(error, RT_ERROR_RUNTIME, "GPU: a shader program does not link: %s", log);
        return 0;
    }
    return program;
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
    const char *parts[2 + 2 * GPU_MAX_SHADER_MODULES];
    char line_directives[GPU_MAX_SHADER_MODULES][32];
    int count = 0;
    parts[count++] = "#version 450 core\n";
    parts[count++] = defines;
    for (int i = 0; shader_modules[i].path != NULL; i++) {
        if (i == GPU_MAX_SHADER_MODULES) {
            rt_error_set(error, RT_ERROR_RUNTIME, "GPU: core/shader_sources.S lists more than %d shader modules "
                         "(GPU_MAX_SHADER_MODULES in core/gpu.c)", GPU_MAX_SHADER_MODULES);
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

/* Builds a program of the shared vertex shader and the fragment program (SHADER_PROGRAM_*)
 * with defines. Returns the program or 0 with error set. */
static GLuint build_fragment_program(uintptr_t program, const char *defines, rt_error *error)
{
    const char *vertex_parts[] = {"#version 450 core\n", shader_source_fullscreen_vertex};
    GLuint vertex = compile_stage(GL_VERTEX_SHADER, vertex_parts, 2, error);
    if (vertex == 0)
        return 0;
    GLuint fragment = compile_fragment_program(program, defines, error);
    if (fragment == 0) {
        glDeleteShader(vertex);
        return 0;
    }
    return link_program(vertex, fragment, error);
}

/* Writes the #defines of a tracer variant into defines (size bytes): every
 * RTSPHERES_OMIT_* as 1 when its GPU_OMIT_* bit is in omitted, else 0 (glsl/variant.glsl
 * reads them), and RTSPHERES_FIX_UNIFORMS with the integrator and sky type it compiles in
 * (0 when not fixed, so the source does not vary with the parameters). */
static void variant_defines(uint32_t omitted, int integrator, int sky_type, char *defines, size_t size)
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
        {GPU_FIX_UNIFORMS, "RTSPHERES_FIX_UNIFORMS"},
    };
    bool fixed = (omitted & GPU_FIX_UNIFORMS) != 0;
    size_t used = 0;
    defines[0] = '\0';
    for (size_t i = 0; i < sizeof features / sizeof features[0] && used < size; i++)
        used += (size_t)snprintf(defines + used, size - used, "#define %s %d\n", features[i].name,
                                 (omitted & features[i].bit) != 0);
    if (used < size)
        snprintf(defines + used, size - used, "#define RTSPHERES_INTEGRATOR %d\n#define RTSPHERES_SKY_TYPE %d\n",
                 fixed ? integrator : 0, fixed ? sky_type : 0);
}

/* The key of a variant in the context's program cache: the bits, and the constants
 * compiled in with GPU_FIX_UNIFORMS. */
static uint32_t variant_key(uint32_t omitted, int integrator, int sky_type)
{
    omitted &= (1u << GPU_VARIANT_BITS) - 1u;
    if (omitted & GPU_FIX_UNIFORMS)
        return omitted | (uint32_t)(integrator & 3) << 16 | (uint32_t)(sky_type & 15) << 20;
    return omitted;
}

/* The context's tracer program for the variant of the parameters (omitted_features,
 * integrator, sky type), compiled on first use and kept (the oldest goes when the cache
 * is full; a render holding it still has it, since only the next render asks again). */
static rt_status build_program(gpu_tracer *tracer, const gpu_tracer_parameters *parameters, rt_error *error)
{
    gpu_context *context = tracer->context;
    uint32_t omitted = parameters->omitted_features;
    int integrator = parameters->shader.integrator, sky_type = parameters->shader.sky_type;
    uint32_t key = variant_key(omitted, integrator, sky_type);
    for (int i = 0; i < context->tracer_program_count; i++)
        if (context->tracer_programs[i].key == key) {
            tracer->program = context->tracer_programs[i].program;
            return RT_OK;
        }
    char defines[1024];
    variant_defines(omitted, integrator, sky_type, defines, sizeof defines);
    GLuint program = build_fragment_program(SHADER_PROGRAM_PASS, defines, error);
    if (program == 0)
        return RT_ERROR_RUNTIME;
    int slot = context->tracer_program_count;
    if (slot == GPU_PROGRAM_CACHE_SIZE) {
        slot = context->next_eviction;
        context->next_eviction = (context->next_eviction + 1) % GPU_PROGRAM_CACHE_SIZE;
        glDeleteProgram(context->tracer_programs[slot].program);
    } else {
        context->tracer_program_count++;
    }
    context->tracer_programs[slot].key = key;
    context->tracer_programs[slot].program = program;
    tracer->program = program;
    return RT_OK;
}

/* Uploads the packed scene into a buffer object read through an RGBA32UI buffer texture
 * (usamplerBuffer), checked against GL_MAX_TEXTURE_BUFFER_SIZE. A buffer texture rather
 * than a 2D one because a fetch from it is a bounds check and a load: on llvmpipe a 2D
 * texelFetch also looks up each lane's mip level and row pitch (docs/performance.md
 * has what that cost). */
static rt_status upload_packed_scene(gpu_tracer *tracer, const uint32_t *texels, uint32_t texel_count,
                                     rt_error *error)
{
    int64_t max_texels = tracer->context->info.max_texture_buffer_size;
    if ((int64_t)texel_count > max_texels)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "GPU: the packed scene needs %u texels of 16 bytes, more than this device's "
                            "buffer textures hold (GL_MAX_TEXTURE_BUFFER_SIZE %lld): %lld texels too many",
                            texel_count, (long long)max_texels, (long long)texel_count - (long long)max_texels);
    /* A zero-sized buffer is not a valid texture store: keep at least one texel. */
    static const uint32_t empty[4] = {0, 0, 0, 0};
    glGenBuffers(1, &tracer->packed_buffer);
    glBindBuffer(GL_TEXTURE_BUFFER, tracer->packed_buffer);
    glBufferData(GL_TEXTURE_BUFFER, (GLsizeiptr)(texel_count ? texel_count : 1) * 4 * (GLsizeiptr)sizeof(uint32_t),
                 texel_count ? (const void *)texels : (const void *)empty, GL_STATIC_DRAW);
    glBindBuffer(GL_TEXTURE_BUFFER, 0);
    glGenTextures(1, &tracer->packed_texture);
    glBindTexture(GL_TEXTURE_BUFFER, tracer->packed_texture);
    glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32UI, tracer->packed_buffer);
    glBindTexture(GL_TEXTURE_BUFFER, 0);
    return check_gl("uploading the packed scene", error);
}

/* Creates both sets of state textures (zeroed) and their framebuffers. */
static rt_status create_state(gpu_tracer *tracer, rt_error *error)
{
    int max_size = tracer->context->info.max_texture_size;
    if (tracer->width > max_size || tracer->height > max_size)
        return rt_error_set(error, RT_ERROR_INPUT,
                            "GPU: the image %dx%d is larger than the device's textures (GL_MAX_TEXTURE_SIZE %d): "
                            "render it in tiles (--tile, --crop) of at most %d pixels a side",
                            tracer->width, tracer->height, max_size, max_size);
    if (tracer->context->info.max_draw_buffers < TRACER_STATE_COUNT)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: the tracer needs %d draw buffers, the device has %d",
                            TRACER_STATE_COUNT, tracer->context->info.max_draw_buffers);
    GLenum draw_buffers[TRACER_STATE_COUNT];
    for (int set = 0; set < 2; set++) {
        glGenTextures(TRACER_STATE_COUNT, tracer->state_textures[set]);
        glGenFramebuffers(1, &tracer->framebuffers[set]);
        glBindFramebuffer(GL_FRAMEBUFFER, tracer->framebuffers[set]);
        for (int target = 0; target < TRACER_STATE_COUNT; target++) {
            bool integer = target == TRACER_STATE_COUNTERS;
            glBindTexture(GL_TEXTURE_2D, tracer->state_textures[set][target]);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            glTexStorage2D(GL_TEXTURE_2D, 1, integer ? GL_RGBA32UI : GL_RGBA32F, tracer->width, tracer->height);
            glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + target, GL_TEXTURE_2D,
                                   tracer->state_textures[set][target], 0);
            draw_buffers[target] = GL_COLOR_ATTACHMENT0 + target;
        }
        glDrawBuffers(TRACER_STATE_COUNT, draw_buffers);
        GLenum complete = glCheckFramebufferStatus(GL_FRAMEBUFFER);
        if (complete != GL_FRAMEBUFFER_COMPLETE)
            return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: the state framebuffer is incomplete (0x%04x)",
                                complete);
        const GLfloat zero[4] = {0, 0, 0, 0};
        const GLuint zero_uint[4] = {0, 0, 0, 0};
        for (int target = 0; target < TRACER_STATE_COUNT; target++) {
            if (target == TRACER_STATE_COUNTERS)
                glClearBufferuiv(GL_COLOR, target, zero_uint);
            else
                glClearBufferfv(GL_COLOR, target, zero);
        }
    }
    rt_status status = check_gl("creating the state textures", error);
    if (status != RT_OK && strstr(error->message, "OUT_OF_MEMORY"))
        return rt_error_set(error, RT_ERROR_INPUT, "GPU: not enough memory for a %dx%d image's state (%d MB)",
                            tracer->width, tracer->height,
                            (int)((double)tracer->width * tracer->height * 16 * 2 * TRACER_STATE_COUNT / 1e6));
    return status;
}

/* Loads a partial result into the state the first pass reads: the accumulated sums
 * and, as "samples started", the finished counts (a path that was in flight is simply
 * traced again: its random numbers are the same). */
static rt_status load_resume_state(gpu_tracer *tracer, const float *resume, rt_error *error)
{
    size_t pixel_count = (size_t)tracer->width * tracer->height;
    float *sums = malloc(pixel_count * 4 * sizeof(float));
    uint32_t *counters = calloc(pixel_count * 4, sizeof(uint32_t));
    if (sums == NULL || counters == NULL) {
        free(sums);
        free(counters);
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory loading the partial render");
    }
    size_t row_floats = (size_t)tracer->width * 4;
    for (int row = 0; row < tracer->height; row++) {
        /* Rows top to bottom in memory; GL's row 0 is the bottom. */
        const float *source = resume + (size_t)(tracer->height - 1 - row) * row_floats;
        memcpy(sums + (size_t)row * row_floats, source, row_floats * sizeof(float));
        for (int x = 0; x < tracer->width; x++)
            counters[((size_t)row * tracer->width + x) * 4] = (uint32_t)source[x * 4 + 3];
    }
    glBindTexture(GL_TEXTURE_2D, tracer->state_textures[0][TRACER_STATE_ACCUMULATED]);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, tracer->width, tracer->height, GL_RGBA, GL_FLOAT, sums);
    glBindTexture(GL_TEXTURE_2D, tracer->state_textures[0][TRACER_STATE_COUNTERS]);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, tracer->width, tracer->height, GL_RGBA_INTEGER, GL_UNSIGNED_INT, counters);
    free(sums);
    free(counters);
    return check_gl("loading the partial render", error);
}

/* Returns budget within what the device's work bound allows (gpu.h). */
static uint32_t clamp_budget(const gpu_info *info, uint32_t budget)
{
    uint32_t most = (uint32_t)info->max_pass_work_budget;
    return budget < 1 ? 1 : budget > most ? most : budget;
}

/* Uploads the tracer's parameter block: the parameters' block with what the device
 * decides (the work cap, the budget within its bound) and full_size defaulted. */
static void upload_parameters(gpu_tracer *tracer)
{
    const gpu_info *info = &tracer->context->info;
    tracer_parameter_block block = tracer->parameters.shader;
    if (block.full_size[0] == 0 || block.full_size[1] == 0) {
        block.full_size[0] = block.image_size[0];
        block.full_size[1] = block.image_size[1];
    }
    block.pass_work_budget = (int32_t)clamp_budget(info, (uint32_t)block.pass_work_budget);
    block.work_cap = info->work_cap;
    tracer->parameters.shader = block;
    glBindBuffer(GL_UNIFORM_BUFFER, tracer->parameter_buffer);
    glBufferData(GL_UNIFORM_BUFFER, sizeof block, &block, GL_DYNAMIC_DRAW);
    glBindBufferBase(GL_UNIFORM_BUFFER, TRACER_PARAMETER_BINDING, tracer->parameter_buffer);
}

/* Changes one int member of the uploaded parameter block (at offset). */
static void update_parameter(gpu_tracer *tracer, size_t offset, int32_t value)
{
    glBindBuffer(GL_UNIFORM_BUFFER, tracer->parameter_buffer);
    glBufferSubData(GL_UNIFORM_BUFFER, (GLintptr)offset, sizeof value, &value);
}

rt_status gpu_tracer_create(gpu_context *context, const uint32_t *packed_texels, uint32_t texel_count,
                            const gpu_tracer_parameters *parameters, gpu_tracer **out, rt_error *error)
{
    *out = NULL;
    gpu_tracer *tracer = calloc(1, sizeof *tracer);
    if (tracer == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory");
    tracer->context = context;
    tracer->width = parameters->shader.image_size[0];
    tracer->height = parameters->shader.image_size[1];
    rt_status status = build_program(tracer, parameters, error);
    uint64_t hash = hash_bytes(HASH_START, packed_texels, (size_t)texel_count * 16u);
    if (status == RT_OK && context->packed_texture != 0 && context->packed_hash == hash
        && context->packed_texel_count == texel_count) {
        tracer->packed_texture = context->packed_texture;
        tracer->packed_buffer = context->packed_buffer;
        tracer->reused_scene = true;
    } else if (status == RT_OK) {
        if (context->packed_texture != 0) {
            glDeleteTextures(1, &context->packed_texture);
            glDeleteBuffers(1, &context->packed_buffer);
            context->packed_texture = 0;
            context->packed_buffer = 0;
        }
        status = upload_packed_scene(tracer, packed_texels, texel_count, error);
        if (status == RT_OK) {
            context->packed_texture = tracer->packed_texture;
            context->packed_buffer = tracer->packed_buffer;
            context->packed_hash = hash;
            context->packed_texel_count = texel_count;
        }
    }
    if (status == RT_OK)
        status = create_state(tracer, error);
    if (status == RT_OK && parameters->resume != NULL)
        status = load_resume_state(tracer, parameters->resume, error);
    if (status != RT_OK) {
        gpu_tracer_destroy(tracer);
        return status;
    }
    glGenVertexArrays(1, &tracer->vertex_array);
    glGenBuffers(1, &tracer->counter_buffer);
    glBindBuffer(GL_ATOMIC_COUNTER_BUFFER, tracer->counter_buffer);
    glBufferData(GL_ATOMIC_COUNTER_BUFFER, 2 * sizeof(GLuint), NULL, GL_DYNAMIC_READ);
    glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, TRACER_COUNTER_BINDING, tracer->counter_buffer);
    tracer->parameters = *parameters;
    tracer->parameters.resume = NULL;
    glGenBuffers(1, &tracer->parameter_buffer);
    upload_parameters(tracer);
    status = check_gl("setting up the tracer", error);
    if (status != RT_OK) {
        gpu_tracer_destroy(tracer);
        return status;
    }
    *out = tracer;
    return RT_OK;
}

rt_status gpu_tracer_run_pass(gpu_tracer *tracer, gpu_pass_report *report, rt_error *error)
{
    int source = tracer->current, target = 1 - tracer->current;
    const GLuint zero[2] = {0, 0};
    glBindBuffer(GL_ATOMIC_COUNTER_BUFFER, tracer->counter_buffer);
    glBufferSubData(GL_ATOMIC_COUNTER_BUFFER, 0, sizeof zero, zero);
    glBindFramebuffer(GL_FRAMEBUFFER, tracer->framebuffers[target]);
    glViewport(0, 0, tracer->width, tracer->height);
    glUseProgram(tracer->program);
    glBindBufferBase(GL_UNIFORM_BUFFER, TRACER_PARAMETER_BINDING, tracer->parameter_buffer);
    glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, TRACER_COUNTER_BINDING, tracer->counter_buffer);
    for (int state = 0; state < TRACER_STATE_COUNT; state++) {
        glActiveTexture(GL_TEXTURE0 + state);
        glBindTexture(GL_TEXTURE_2D, tracer->state_textures[source][state]);
    }
    glActiveTexture(GL_TEXTURE0 + TRACER_PACKED_SCENE_UNIT);
    glBindTexture(GL_TEXTURE_BUFFER, tracer->packed_texture);
    glBindVertexArray(tracer->vertex_array);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glMemoryBarrier(GL_ATOMIC_COUNTER_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    GLuint counters[2] = {0, 0};
    glGetBufferSubData(GL_ATOMIC_COUNTER_BUFFER, 0, sizeof counters, counters);
    tracer->current = target;
    report->unfinished_pixels = counters[0];
    report->samples_finished = counters[1];
    return check_gl("a tracer pass", error);
}

void gpu_tracer_set_pass_work_budget(gpu_tracer *tracer, uint32_t budget)
{
    tracer->parameters.shader.pass_work_budget = (int32_t)clamp_budget(&tracer->context->info, budget);
    update_parameter(tracer, offsetof(tracer_parameter_block, pass_work_budget),
                     tracer->parameters.shader.pass_work_budget);
}

/* Reads one state texture of the latest set into rows top to bottom. */
static void read_state(gpu_tracer *tracer, int state, float *rgba)
{
    size_t row_floats = (size_t)tracer->width * 4;
    float *bottom_up = malloc(row_floats * tracer->height * sizeof(float));
    if (bottom_up == NULL)
        return;
    glBindTexture(GL_TEXTURE_2D, tracer->state_textures[tracer->current][state]);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, bottom_up);
    for (int row = 0; row < tracer->height; row++)
        memcpy(rgba + (size_t)row * row_floats, bottom_up + (size_t)(tracer->height - 1 - row) * row_floats,
               row_floats * sizeof(float));
    free(bottom_up);
}

rt_status gpu_tracer_read(gpu_tracer *tracer, float *rgba, float *luminance_squares, gpu_tracer_totals *totals,
                          rt_error *error)
{
    glActiveTexture(GL_TEXTURE0);
    read_state(tracer, TRACER_STATE_ACCUMULATED, rgba);
    if (totals != NULL || luminance_squares != NULL) {
        size_t count = (size_t)tracer->width * tracer->height;
        float *statistics = malloc(count * 4 * sizeof(float));
        if (statistics == NULL)
            return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory reading statistics");
        read_state(tracer, TRACER_STATE_STATISTICS, statistics);
        gpu_tracer_totals sums = {0};
        for (size_t i = 0; i < count; i++) {
            sums.path_segments += statistics[i * 4 + 0];
            sums.traversal_overflows += statistics[i * 4 + 1];
            if (luminance_squares != NULL)
                luminance_squares[i] = statistics[i * 4 + 2];
        }
        if (totals != NULL)
            *totals = sums;
        free(statistics);
    }
    return check_gl("reading the result", error);
}

rt_status gpu_tracer_render_aovs(gpu_tracer *tracer, int samples, float *albedo_depth, float *normal_coverage,
                                 rt_error *error)
{
    /* The render's variant: the AOV pass reaches no more of the tracer than the render. */
    char defines[1024];
    const gpu_tracer_parameters *p = &tracer->parameters;
    variant_defines(p->omitted_features, p->shader.integrator, p->shader.sky_type, defines, sizeof defines);
    GLuint program = build_fragment_program(SHADER_PROGRAM_AOV, defines, error);
    if (program == 0)
        return RT_ERROR_RUNTIME;
    int width = tracer->width, height = tracer->height;
    GLuint textures[2], framebuffer;
    glGenTextures(2, textures);
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    for (int k = 0; k < 2; k++) {
        glBindTexture(GL_TEXTURE_2D, textures[k]);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, width, height);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + k, GL_TEXTURE_2D, textures[k], 0);
    }
    const GLenum draw_buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, draw_buffers);
    rt_status status = RT_OK;
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        status = rt_error_set(error, RT_ERROR_RUNTIME, "GPU: the AOV framebuffer is incomplete");
    if (status == RT_OK) {
        update_parameter(tracer, offsetof(tracer_parameter_block, aov_samples), samples);
        glUseProgram(program);
        glBindBufferBase(GL_UNIFORM_BUFFER, TRACER_PARAMETER_BINDING, tracer->parameter_buffer);
        glViewport(0, 0, width, height);
        glActiveTexture(GL_TEXTURE0 + TRACER_PACKED_SCENE_UNIT);
        glBindTexture(GL_TEXTURE_BUFFER, tracer->packed_texture);
        glBindVertexArray(tracer->vertex_array);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        float *outputs[2] = {albedo_depth, normal_coverage};
        size_t row_floats = (size_t)width * 4;
        float *bottom_up = malloc(row_floats * (size_t)height * sizeof(float));
        if (bottom_up == NULL)
            status = rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory reading the AOVs");
        for (int k = 0; k < 2 && status == RT_OK; k++) {
            glReadBuffer(GL_COLOR_ATTACHMENT0 + k);
            glPixelStorei(GL_PACK_ALIGNMENT, 4);
            glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, bottom_up);
            for (int row = 0; row < height; row++)
                memcpy(outputs[k] + (size_t)row * row_floats, bottom_up + (size_t)(height - 1 - row) * row_floats,
                       row_floats * sizeof(float));
        }
        free(bottom_up);
    }
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteTextures(2, textures);
    glDeleteProgram(program);
    glUseProgram(tracer->program);
    if (status != RT_OK)
        return status;
    return check_gl("the AOV pass", error);
}

bool gpu_tracer_reused_scene(const gpu_tracer *tracer)
{
    return tracer->reused_scene;
}

void gpu_tracer_destroy(gpu_tracer *tracer)
{
    if (tracer == NULL)
        return;
    for (int set = 0; set < 2; set++) {
        glDeleteTextures(TRACER_STATE_COUNT, tracer->state_textures[set]);
        glDeleteFramebuffers(1, &tracer->framebuffers[set]);
    }
    /* The program and the packed scene belong to the context (kept for the next frame). */
    if (tracer->packed_texture != tracer->context->packed_texture) {
        glDeleteTextures(1, &tracer->packed_texture);
        glDeleteBuffers(1, &tracer->packed_buffer);
    }
    glDeleteBuffers(1, &tracer->counter_buffer);
    glDeleteBuffers(1, &tracer->parameter_buffer);
    glDeleteVertexArrays(1, &tracer->vertex_array);
    free(tracer);
}

rt_status gpu_random_numbers(gpu_context *context, int width, int height, uint32_t sample_index, uint32_t seed,
                             uint32_t dimension, float *rgba, rt_error *error)
{
    (void)context;
    GLuint program = build_fragment_program(SHADER_PROGRAM_RANDOM_TEST, "", error);
    if (program == 0)
        return RT_ERROR_RUNTIME;
    GLuint texture, framebuffer, vertex_array;
    glGenTextures(1, &texture);
    glBindTexture(GL_TEXTURE_2D, texture);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, width, height);
    glGenFramebuffers(1, &framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture, 0);
    GLenum draw_buffer = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &draw_buffer);
    glGenVertexArrays(1, &vertex_array);
    glBindVertexArray(vertex_array);
    glViewport(0, 0, width, height);
    glUseProgram(program);
    glUniform1ui(glGetUniformLocation(program, "sample_index"), sample_index);
    glUniform1ui(glGetUniformLocation(program, "seed"), seed);
    glUniform1ui(glGetUniformLocation(program, "dimension"), dimension);
    glUniform1i(glGetUniformLocation(program, "image_height"), height);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    size_t row_floats = (size_t)width * 4;
    float *bottom_up = malloc(row_floats * (size_t)height * sizeof(float));
    if (bottom_up != NULL) {
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, bottom_up);
        for (int row = 0; row < height; row++)
            memcpy(rgba + (size_t)row * row_floats, bottom_up + (size_t)(height - 1 - row) * row_floats,
                   row_floats * sizeof(float));
        free(bottom_up);
    }
    glDeleteVertexArrays(1, &vertex_array);
    glDeleteFramebuffers(1, &framebuffer);
    glDeleteTextures(1, &texture);
    glDeleteProgram(program);
    if (bottom_up == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory reading random numbers");
    return check_gl("drawing random numbers", error);
}

rt_status gpu_tracer_parameter_layout(gpu_context *context, int count, const char *const *names, int *offsets,
                                      int *block_size, rt_error *error)
{
    (void)context;
    char defines[1024];
    variant_defines(0, 0, 0, defines, sizeof defines);
    GLuint program = build_fragment_program(SHADER_PROGRAM_PASS, defines, error);
    if (program == 0)
        return RT_ERROR_RUNTIME;
    for (int i = 0; i < count; i++) {
        GLuint index = GL_INVALID_INDEX;
        glGetUniformIndices(program, 1, &names[i], &index);
        offsets[i] = -1;
        if (index != GL_INVALID_INDEX)
            glGetActiveUniformsiv(program, 1, &index, GL_UNIFORM_OFFSET, &offsets[i]);
    }
    *block_size = 0;
    GLuint block = glGetUniformBlockIndex(program, "tracer_parameter_block");
    if (block != GL_INVALID_INDEX)
        glGetActiveUniformBlockiv(program, block, GL_UNIFORM_BLOCK_DATA_SIZE, block_size);
    glDeleteProgram(program);
    return check_gl("reading the parameter block's layout", error);
}
