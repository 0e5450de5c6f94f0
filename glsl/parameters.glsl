// parameters.glsl: what every tracer program reads besides its pass state: the parameter
// block, the packed scene, and the constants the other files share.
//
// The tracer is one GLSL source made of the files of the module table in
// core/shader_sources.S, in its order, after "#version 450 core" and the variant's
// defines (core/gpu_program.c compile_fragment_program). core/tracer_interface.h and
// core/packed_layout.h come first, so every id, tag and record offset below is the one C
// uses too.

// The parameter block: core/tracer_interface.h lists its members (the same list makes the
// C struct tracer_parameter_block of core/gpu.h). The block's members are called
// TRACER_BLOCK_MEMBER(NAME) (block_NAME); the rest of the tracer reads a global copy of
// each by its own name (image_size, seed, ...), which read_parameters() makes first thing
// in every main().
//
// Why copies: llvmpipe reads a uniform block member as a bounds-checked load for every
// lane (a dozen instructions), and reads it again wherever it is used, in every iteration
// of every loop (the loops' image stores keep LLVM from hoisting the loads). The GLSL
// compiler would put a plain copy of a uniform back in its uses, so each copy goes through
// opaque(), which adds a zero the compiler cannot see is zero. The weekend's segment loop:
// 3,147 instructions with the loads, 2,421 with the copies (docs/performance.md, the log).
#define TRACER_GLSL_MEMBER(type, name) type TRACER_BLOCK_MEMBER(name);
layout(std140, binding = TRACER_PARAMETER_BINDING) uniform tracer_parameter_block {
    TRACER_PARAMETERS(TRACER_GLSL_MEMBER)
};
#define TRACER_GLSL_GLOBAL(type, name) type name;
TRACER_PARAMETERS(TRACER_GLSL_GLOBAL)

uint opaque_zero;   // 0, from a test on gl_FragCoord no compiler can decide
int opaque(int x) { return x + int(opaque_zero); }
uint opaque(uint x) { return x + opaque_zero; }
float opaque(float x) { return uintBitsToFloat(floatBitsToUint(x) + opaque_zero); }
ivec2 opaque(ivec2 x) { return x + int(opaque_zero); }
uvec2 opaque(uvec2 x) { return x + opaque_zero; }
vec3 opaque(vec3 x) { return uintBitsToFloat(floatBitsToUint(x) + opaque_zero); }

// Copies the parameter block into the globals of the same names (above).
#define TRACER_GLSL_COPY(type, name) name = opaque(TRACER_BLOCK_MEMBER(name));
void read_parameters()
{
    opaque_zero = uint(gl_FragCoord.x < -1.0);
    TRACER_PARAMETERS(TRACER_GLSL_COPY)
}

// The packed scene (core/packed_layout.h): texel i is imageLoad(packed_scene, i), an
// image rather than a usamplerBuffer for llvmpipe's sake (glsl/scene_access.glsl).
layout(binding = TRACER_PACKED_SCENE_IMAGE_UNIT, rgba32ui) uniform readonly restrict uimageBuffer packed_scene;

const float INFINITY = 1.0 / 0.0;
const float PI = 3.14159265358979;
const uint NONE = PACKED_NONE;
