/* shader_sources.S: embeds the GLSL sources (and the shared record layout) into the
 * binary with the assembler's .incbin, so rtspheres runs from any directory. Paths are
 * relative to the top of the source tree (the Makefile assembles with -Wa,-I.).
 * Each source is NUL-terminated. Declared in shader_sources.h. */
    .section .rodata
    .global shader_source_packed_layout
shader_source_packed_layout:
    .incbin "core/packed_layout.h"
    .byte 0

    .global shader_source_fullscreen_vertex
shader_source_fullscreen_vertex:
    .incbin "glsl/fullscreen.vert"
    .byte 0

    .global shader_source_random
shader_source_random:
    .incbin "glsl/random.glsl"
    .byte 0

    .global shader_source_random_test_fragment
shader_source_random_test_fragment:
    .incbin "glsl/random_test.frag"
    .byte 0

    .global shader_source_tracer_fragment
shader_source_tracer_fragment:
    .incbin "glsl/tracer.frag"
    .byte 0

    .section .note.GNU-stack,"",@progbits
