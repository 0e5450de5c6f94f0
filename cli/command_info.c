/* command_info.c: `rtspheres info`: which EGL platform/device and OpenGL renderer a
 * render would use, and the limits that matter. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "gpu.h"
#include "large_pages.h"
#include "version.h"

static void print_help(FILE *stream)
{
    fprintf(stream, "usage: rtspheres info [--device N] [--threads N]\n"
                    "  --device N   use EGL device N (0-based, as listed under \"EGL devices\") instead of choosing\n"
                    "  --threads N  CPU threads of a software device (llvmpipe), as render --threads sets them\n");
}

/* Lists the EGL devices with their numbers (what --device N takes) and what EGL tells of
 * each, the one used marked with '*'. */
static void print_devices(const gpu_info *info)
{
    if (info->device_count == 0) {
        printf("EGL devices:      none (no EGL_EXT_platform_device driver; --device cannot be used)\n");
        return;
    }
    printf("EGL devices:      %d (--device N uses device N; %s)\n", info->device_count,
           info->device_index < 0 ? "none is used: the Mesa surfaceless platform is" : "* marks the one used");
    for (int i = 0; i < info->device_count; i++) {
        const gpu_device_description *d = &info->devices[i];
        char known[1024] = "";
        size_t used = 0;
#define KNOWN(...) (used += (size_t)snprintf(known + used, used < sizeof known ? sizeof known - used : 0, __VA_ARGS__))
        KNOWN("%s", d->software ? "software (EGL_MESA_device_software)" : "hardware");
        if (d->vendor[0] != '\0')
            KNOWN(", vendor %s", d->vendor);
        if (d->renderer[0] != '\0')
            KNOWN(", renderer %s", d->renderer);
        if (d->driver[0] != '\0')
            KNOWN(", driver %s", d->driver);
        if (d->drm_device_file[0] != '\0')
            KNOWN(", DRM %s", d->drm_device_file);
        if (d->drm_render_node[0] != '\0')
            KNOWN(", render node %s", d->drm_render_node);
        if (d->software && info->device_index < 0 && strcmp(info->platform, "surfaceless") == 0)
            KNOWN("; the surfaceless platform (the same llvmpipe) is preferred to it");
#undef KNOWN
        printf("  %c device %d:     %s\n", i == info->device_index ? '*' : ' ', i, known);
        printf("      extensions: %s\n", d->extensions[0] != '\0' ? d->extensions : "(none)");
    }
}

int command_info(int argc, char **argv)
{
    static const struct option long_options[] = {
        {"device", required_argument, NULL, 'd'},
        {"threads", required_argument, NULL, 't'},
        {"help", no_argument, NULL, 'h'},
        {NULL, 0, NULL, 0},
    };
    gpu_options options = gpu_options_defaults();
    int option;
    while ((option = getopt_long(argc, argv, "h", long_options, NULL)) != -1) {
        switch (option) {
        case 'd': {
            long long device;
            if (command_parse_integer(optarg, 0, 255, &device) != 0) {
                fprintf(stderr, "rtspheres info: --device wants a device number (0, 1, ...), not '%s'\n", optarg);
                return EXIT_BAD_INPUT;
            }
            options.device = (int)device + 1;
            break;
        }
        case 't': {
            long long threads;
            if (command_parse_integer(optarg, 1, GPU_MAX_THREADS, &threads) != 0) {
                fprintf(stderr, "rtspheres info: --threads wants a whole number from 1 to %d, not '%s'\n",
                        GPU_MAX_THREADS, optarg);
                return EXIT_BAD_INPUT;
            }
            options.threads = (int)threads;
            break;
        }
        default:
            return command_help_exit(option, print_help);
        }
    }
    if (optind < argc) {
        fprintf(stderr, "rtspheres info: unexpected argument '%s'\n", argv[optind]);
        return EXIT_BAD_INPUT;
    }
    gpu_context *context = NULL;
    rt_error error = {{0}};
    rt_status status = gpu_create(&options, &context, &error);
    if (status != RT_OK) {
        fprintf(stderr, "rtspheres info: %s\n", error.message);
        return exit_code_for_status(status);
    }
    gpu_info info;
    gpu_get_info(context, &info);
    printf("rtspheres %s\n", RTSPHERES_VERSION);
    if (info.device_index >= 0)
        printf("EGL platform:     device %d of %d (%s)\n", info.device_index, info.device_count,
               info.device_extensions);
    else
        printf("EGL platform:     %s (Mesa), %d EGL device%s seen\n", info.platform, info.device_count,
               info.device_count == 1 ? "" : "s");
    print_devices(&info);
    printf("EGL:              %s, %s\n", info.egl_vendor, info.egl_version);
    printf("GL vendor:        %s\n", info.gl_vendor);
    printf("GL renderer:      %s%s\n", info.gl_renderer, info.software ? " (software, on the CPU)" : "");
    if (info.software)
        printf("CPU threads:      %d llvmpipe rasteriser thread%s (--threads N, LP_NUM_THREADS)\n",
               info.software_threads, info.software_threads == 1 ? "" : "s");
    else if (info.threads_ignored)
        printf("CPU threads:      --threads does nothing on a hardware device\n");
    printf("huge pages:       %s for large blocks (a 4 KiB page's first touch %.1f us; RTSPHERES_HUGE_PAGES)\n",
           large_pages_advising() ? "yes" : "no", large_pages_fault_microseconds());
    printf("GL version:       %s\n", info.gl_version);
    printf("GLSL version:     %s\n", info.glsl_version);
    printf("max texture size: %d\n", info.max_texture_size);
    printf("max tile side:    %d (larger images render in tiles)\n", info.max_tile_side);
    printf("max texture buffer size: %d texels (the packed scene's limit)\n", info.max_texture_buffer_size);
    if (info.simd_lanes > 0)
        printf("work bound:       %d lanes per shader invocation under a 65,535-iteration loop cap: "
               "work cap %d, pass budget at most %d\n", info.simd_lanes, info.work_cap, info.max_pass_work_budget);
    else
        printf("work bound:       no loop-iteration cap: work cap %d, pass budget at most %d\n", info.work_cap,
               info.max_pass_work_budget);
    printf("max draw buffers: %d\n", info.max_draw_buffers);
    printf("max fragment atomic counters: %d\n", info.max_fragment_atomic_counters);
    printf("max fragment image units: %d (of images and outputs together: %d)\n", info.max_fragment_image_units,
           info.max_images_and_outputs);
    gpu_destroy(context);
    return EXIT_OK;
}
