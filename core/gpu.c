/* gpu.c: the EGL context: devices, context creation, what the device offers. With the
 * tracer's files (core/gpu_tracer.c and those gpu_internal.h names) the only files that
 * call egl* and gl*. See gpu.h for the order of set-up and how failures are told apart. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "gpu_internal.h"

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
    /* A tile is a texture and a framebuffer's attachment: it must fit every one of these. */
    GLint framebuffer_width = 0, framebuffer_height = 0, renderbuffer_size = 0;
    glGetIntegerv(GL_MAX_FRAMEBUFFER_WIDTH, &framebuffer_width);
    glGetIntegerv(GL_MAX_FRAMEBUFFER_HEIGHT, &framebuffer_height);
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &renderbuffer_size);
    info->max_tile_side = info->max_texture_size;
    const GLint side_limits[3] = {framebuffer_width, framebuffer_height, renderbuffer_size};
    for (int i = 0; i < 3; i++)
        if (side_limits[i] > 0 && side_limits[i] < info->max_tile_side)
            info->max_tile_side = side_limits[i];
    /* For tests of images wider than the device, which a real device's 16384 or 32768
     * would make far too slow for a test: lowers, never raises, the tile side. */
    const char *test_side = getenv("RTSPHERES_TEST_MAX_TEXTURE_SIZE");
    if (test_side != NULL && atoi(test_side) > 0 && atoi(test_side) < info->max_tile_side)
        info->max_tile_side = atoi(test_side);
    /* For tests of the "scene too large" path, which no real test scene could reach
     * (134M texels is 2 GiB): RTSPHERES_TEST_MAX_TEXTURE_BUFFER_SIZE lowers, never
     * raises, the limit. */
    const char *test_limit = getenv("RTSPHERES_TEST_MAX_TEXTURE_BUFFER_SIZE");
    if (test_limit != NULL && atoi(test_limit) > 0 && atoi(test_limit) < info->max_texture_buffer_size)
        info->max_texture_buffer_size = atoi(test_limit);
    glGetIntegerv(GL_MAX_DRAW_BUFFERS, &info->max_draw_buffers);
    glGetIntegerv(GL_MAX_COLOR_ATTACHMENTS, &info->max_color_attachments);
    glGetIntegerv(GL_MAX_FRAGMENT_ATOMIC_COUNTERS, &info->max_fragment_atomic_counters);
    glGetIntegerv(GL_MAX_FRAGMENT_IMAGE_UNIFORMS, &info->max_fragment_image_units);
    glGetIntegerv(GL_MAX_COMBINED_IMAGE_UNITS_AND_FRAGMENT_OUTPUTS, &info->max_images_and_outputs);
    info->software = strstr(info->gl_renderer, "llvmpipe") != NULL || strstr(info->gl_renderer, "softpipe") != NULL
                     || strstr(info->gl_renderer, "swrast") != NULL;
    set_work_limits(info);
}

/* Counts this process's llvmpipe rasteriser threads: llvmpipe names each "llvmpipe-N"
 * (its thread index), which /proc/self/task/TID/comm shows. Returns the count, or -1 when
 * /proc cannot be read. */
static int count_software_threads(void)
{
    DIR *tasks = opendir("/proc/self/task");
    if (tasks == NULL)
        return -1;
    int count = 0;
    struct dirent *entry;
    while ((entry = readdir(tasks)) != NULL) {
        if (entry->d_name[0] == '.')
            continue;
        char path[300], name[64] = "";
        snprintf(path, sizeof path, "/proc/self/task/%s/comm", entry->d_name);
        FILE *file = fopen(path, "r");
        if (file == NULL)
            continue;
        if (fgets(name, sizeof name, file) != NULL && strncmp(name, "llvmpipe-", 9) == 0)
            count++;
        fclose(file);
    }
    closedir(tasks);
    return count;
}

/* Counts the rasteriser threads once they have all named themselves: llvmpipe starts
 * them as its screen is made and each sets its name when it first runs, which on a loaded
 * machine can come after the context exists (a likely cause of one failure of
 * tests/render/test-farm.sh's --threads check under `make test`, not reproduced since).
 * So the count is read again, every 10 ms for at most half a second, while it is below
 * expected (the threads asked for, or LP_NUM_THREADS; by default at least one on a
 * machine of several CPUs, where llvmpipe runs one per CPU). */
static int settled_software_threads(int asked)
{
    int expected = asked;
    const char *environment = getenv("LP_NUM_THREADS");
    if (expected <= 0)
        expected = environment != NULL ? atoi(environment) : sysconf(_SC_NPROCESSORS_ONLN) > 1 ? 1 : 0;
    int count = count_software_threads();
    for (int tries = 0; tries < 50 && count >= 0 && count < expected; tries++) {
        struct timespec pause = {0, 10 * 1000 * 1000};
        nanosleep(&pause, NULL);
        count = count_software_threads();
    }
    return count;
}

/* The environment's LP_NUM_THREADS before gpu_create() changed it, to put back. */
typedef struct thread_setting {
    bool changed;
    char *previous;              /* NULL: it was not set */
} thread_setting;

/* Sets LP_NUM_THREADS to threads (> 0) for the context about to be made, keeping what was
 * there in *saved; threads 0 leaves the environment alone. */
static void set_software_threads(int threads, thread_setting *saved)
{
    memset(saved, 0, sizeof *saved);
    if (threads <= 0)
        return;
    const char *previous = getenv("LP_NUM_THREADS");
    saved->previous = previous != NULL ? strdup(previous) : NULL;
    saved->changed = true;
    char value[16];
    snprintf(value, sizeof value, "%d", threads);
    setenv("LP_NUM_THREADS", value, 1);
}

/* Puts LP_NUM_THREADS back as *saved has it (llvmpipe has read it by now), so child
 * processes and later contexts see the caller's environment. */
static void restore_software_threads(thread_setting *saved)
{
    if (!saved->changed)
        return;
    if (saved->previous != NULL)
        setenv("LP_NUM_THREADS", saved->previous, 1);
    else
        unsetenv("LP_NUM_THREADS");
    free(saved->previous);
    memset(saved, 0, sizeof *saved);
}

static rt_status create_display_and_context(gpu_context *context, rt_error *error);

rt_status gpu_create(const gpu_options *options, gpu_context **out, rt_error *error)
{
    *out = NULL;
    int threads = options != NULL ? options->threads : 0;
    if (threads < 0 || threads > GPU_MAX_THREADS)
        return rt_error_set(error, RT_ERROR_INPUT, "GPU: %d threads asked for; 1 to %d, or 0 for the default",
                            threads, GPU_MAX_THREADS);
    gpu_context *context = calloc(1, sizeof *context);
    if (context == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "GPU: out of memory");
    context->options = options ? *options : gpu_options_defaults();
    thread_setting saved;
    set_software_threads(threads, &saved);
    rt_status status = create_display_and_context(context, error);
    restore_software_threads(&saved);
    if (status != RT_OK) {
        free(context);
        return status;
    }
    read_gl_info(context);
    context->info.software_threads =
        context->info.software ? settled_software_threads(threads) : count_software_threads();
    context->info.threads_ignored = threads > 0 && !context->info.software;
    if (context->options.debug_output && epoxy_has_gl_extension("GL_KHR_debug")) {
        glEnable(GL_DEBUG_OUTPUT);
        glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
        glDebugMessageCallback(debug_message_callback, context);
    }
    *out = context;
    return RT_OK;
}

/* The EGL half of gpu_create(): finds a device or platform and makes the context current
 * on it (see gpu.h for the order). On failure context is left for the caller to free. */
static rt_status create_display_and_context(gpu_context *context, rt_error *error)
{
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
        if (tried[0] != '\0')
            return rt_error_set(error, RT_ERROR_RUNTIME, "%s", tried);
        if (attempt.message[0] != '\0')
            return rt_error_set(error, status, "%s", attempt.message);
        return rt_error_set(error, RT_ERROR_NO_DEVICE,
                            "GPU: no usable EGL device: no GPU driver offers EGL_EXT_platform_device and Mesa's "
                            "surfaceless platform is missing. Install Mesa (apt-get install libegl-mesa0 "
                            "libgl1-mesa-dri) or your GPU vendor's EGL driver");
    }
    return RT_OK;
}

void gpu_destroy(gpu_context *context)
{
    if (context == NULL)
        return;
    gpu_tracer_release(context);
    eglMakeCurrent(context->display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(context->display, context->context);
    eglTerminate(context->display);
    free(context);
}

void gpu_get_info(const gpu_context *context, gpu_info *info)
{
    *info = context->info;
}
