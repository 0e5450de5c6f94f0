/* shader_sources.S: embeds the GLSL sources (and the headers shared with C) into the
 * binary with the assembler's .incbin, so rtspheres runs from any directory. Paths are
 * relative to the top of the source tree (the Makefile assembles with -Wa,-I.). Each
 * source is NUL-terminated. Declared in shader_sources.h, which says how programs are
 * assembled from the table below.
 *
 * THE MODULE TABLE is the one list of the fragment programs' sources, in the order they
 * are joined: a file may use what the files above it define. A new GLSL file is one line
 * here (a material among the materials, an integrator before glsl/integrators.glsl), its
 * programs being SHADER_PROGRAM_* bits of shader_sources.h. The material test program
 * (gpu.h gpu_material_test) is the modules up to the table of materials and its main; the
 * light choice test program (gpu.h gpu_light_choice_test) the modules up to the lights
 * and its main. */
#include "shader_sources.h"

    /* module PATH, PROGRAMS: the file's text (NUL-terminated) and its path in .rodata, and
     * a table entry (path, source, programs) in .data.rel.ro */
    .macro module path, programs
    .section .rodata
1:  .incbin "\path"
    .byte 0
2:  .asciz "\path"
    .section .data.rel.ro
    .dc.a 2b, 1b, \programs
    .endm

    .section .data.rel.ro
    .balign 16
    .global shader_modules
shader_modules:
    /* ids, parameters */
    module "core/tracer_interface.h", SHADER_PROGRAM_SHADING|SHADER_PROGRAM_RANDOM_TEST|SHADER_PROGRAM_CULL
    module "core/packed_layout.h", SHADER_PROGRAM_SHADING|SHADER_PROGRAM_CULL /* the packed scene's records */
    module "glsl/random.glsl", SHADER_PROGRAM_SHADING|SHADER_PROGRAM_RANDOM_TEST
    module "glsl/random_test.frag", SHADER_PROGRAM_RANDOM_TEST
    module "glsl/parameters.glsl", SHADER_PROGRAM_SHADING|SHADER_PROGRAM_CULL
    module "glsl/cull.frag", SHADER_PROGRAM_CULL
    module "glsl/variant.glsl", SHADER_PROGRAM_SHADING
    module "glsl/work.glsl", SHADER_PROGRAM_SHADING
    module "glsl/sampling.glsl", SHADER_PROGRAM_SHADING
    module "glsl/camera.glsl", SHADER_PROGRAM_SHADING
    module "glsl/scene_access.glsl", SHADER_PROGRAM_SHADING
    module "glsl/textures.glsl", SHADER_PROGRAM_SHADING             /* before intersect: alpha masks */
    module "glsl/intersect.glsl", SHADER_PROGRAM_SHADING
    module "glsl/traverse.glsl", SHADER_PROGRAM_SHADING
    module "glsl/sky.glsl", SHADER_PROGRAM_SHADING
    module "glsl/surface.glsl", SHADER_PROGRAM_SHADING
    module "glsl/media.glsl", SHADER_PROGRAM_SHADING
    module "glsl/material.glsl", SHADER_PROGRAM_SHADING             /* the material interface */
    module "glsl/material_lambertian.glsl", SHADER_PROGRAM_SHADING
    module "glsl/material_metal.glsl", SHADER_PROGRAM_SHADING
    module "glsl/material_dielectric.glsl", SHADER_PROGRAM_SHADING
    module "glsl/material_emissive.glsl", SHADER_PROGRAM_SHADING
    module "glsl/microfacet.glsl", SHADER_PROGRAM_SHADING           /* GGX, for pbr */
    module "glsl/material_pbr.glsl", SHADER_PROGRAM_SHADING
    module "glsl/material_phong.glsl", SHADER_PROGRAM_SHADING       /* Whitted's shading model */
    module "glsl/material_table.glsl", SHADER_PROGRAM_SHADING       /* the table of materials */
    module "glsl/material_test.frag", SHADER_PROGRAM_MATERIAL_TEST
    module "glsl/light_groups.glsl", SHADER_PROGRAM_LIGHTS         /* --light-groups layers */
    module "glsl/lights.glsl", SHADER_PROGRAM_LIGHTS
    module "glsl/light_test.frag", SHADER_PROGRAM_LIGHT_TEST
    module "glsl/direct_light.glsl", SHADER_PROGRAM_TRACER
    module "glsl/path_state.glsl", SHADER_PROGRAM_TRACER
    module "glsl/integrator_path.glsl", SHADER_PROGRAM_PASS
    module "glsl/integrator_whitted.glsl", SHADER_PROGRAM_PASS
    module "glsl/direct_emission.glsl", SHADER_PROGRAM_PASS       /* --denoise's direct emission */
    module "glsl/integrators.glsl", SHADER_PROGRAM_PASS             /* the table of integrators */
    module "glsl/pass_state.glsl", SHADER_PROGRAM_PASS
    module "glsl/main.glsl", SHADER_PROGRAM_PASS
    module "glsl/aov.glsl", SHADER_PROGRAM_AOV
    .dc.a 0, 0, 0

    .section .rodata
    .global shader_source_fullscreen_vertex
shader_source_fullscreen_vertex:
    .incbin "glsl/fullscreen.vert"
    .byte 0

    .section .note.GNU-stack,"",@progbits
