/* shader_sources.h: the GLSL sources embedded by shader_sources.S (NUL-terminated).
 *
 * The fragment programs are made of modules: core/gpu_program.c (compile_fragment_program) joins
 * "#version 450 core", the program's defines and, in the order of the module table of
 * shader_sources.S, every module whose programs include that program. The vertex shader
 * (one triangle over the viewport) is shared by all programs.
 *
 * This header is also read by the assembler (for the SHADER_PROGRAM_* bits), so
 * everything but the #defines is hidden from it. */
#ifndef RT_SHADER_SOURCES_H
#define RT_SHADER_SOURCES_H

/* The fragment programs a module belongs to (shader_module.programs). */
#define SHADER_PROGRAM_PASS 1           /* a tracer pass (glsl/main.glsl) */
#define SHADER_PROGRAM_AOV 2            /* the AOV pass (glsl/aov.glsl) */
#define SHADER_PROGRAM_RANDOM_TEST 4    /* the random-number test (glsl/random_test.frag) */
#define SHADER_PROGRAM_MATERIAL_TEST 8  /* the material test (glsl/material_test.frag) */
#define SHADER_PROGRAM_LIGHT_TEST 16    /* the light choice test (glsl/light_test.frag) */
#define SHADER_PROGRAM_CULL 32          /* the finished pixels' depth mark (glsl/cull.frag) */
#define SHADER_PROGRAM_TRACER (SHADER_PROGRAM_PASS|SHADER_PROGRAM_AOV)   /* no spaces: an assembler macro argument */
/* The modules up to the materials: the tracer's, and the material and light tests'. */
#define SHADER_PROGRAM_SHADING (SHADER_PROGRAM_PASS|SHADER_PROGRAM_AOV|SHADER_PROGRAM_MATERIAL_TEST|SHADER_PROGRAM_LIGHT_TEST)
/* The modules up to the lights: the tracer's, and the light test's. */
#define SHADER_PROGRAM_LIGHTS (SHADER_PROGRAM_PASS|SHADER_PROGRAM_AOV|SHADER_PROGRAM_LIGHT_TEST)

#ifndef __ASSEMBLER__
#include <stdint.h>

typedef struct shader_module {
    const char *path;            /* e.g. "glsl/traverse.glsl", for messages */
    const char *source;
    uintptr_t programs;          /* SHADER_PROGRAM_* bits */
} shader_module;

/* The module table, ended by an entry whose path is NULL. */
extern const shader_module shader_modules[];
extern const char shader_source_fullscreen_vertex[];
#endif

#endif
