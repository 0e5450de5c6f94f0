/* shader_sources.h: the GLSL sources embedded by shader_sources.S (NUL-terminated).
 * The tracer is compiled as "#version 450 core" + packed_layout.h + random.glsl +
 * tracer.frag; the RNG test shader as "#version 450 core" + random.glsl + random_test.frag. */
#ifndef RT_SHADER_SOURCES_H
#define RT_SHADER_SOURCES_H
extern const char shader_source_packed_layout[];
extern const char shader_source_fullscreen_vertex[];
extern const char shader_source_random[];
extern const char shader_source_random_test_fragment[];
extern const char shader_source_tracer_fragment[];
#endif
