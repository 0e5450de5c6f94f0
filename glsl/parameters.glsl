// parameters.glsl: what every tracer program reads besides its pass state: the parameter
// block, the packed scene, and the constants the other files share.
//
// The tracer is one GLSL source made of the files of the module table in
// core/shader_sources.S, in its order, after "#version 450 core" and the variant's
// defines (core/gpu_tracer.c compile_fragment_program). core/tracer_interface.h and
// core/packed_layout.h come first, so every id, tag and record offset below is the one C
// uses too.

// The parameter block: core/tracer_interface.h lists its members (the same list makes the
// C struct tracer_parameter_block of core/gpu.h). No instance name: members are read by
// their own names (image_size, seed, ...).
#define TRACER_GLSL_MEMBER(type, name) type name;
layout(std140, binding = TRACER_PARAMETER_BINDING) uniform tracer_parameter_block {
    TRACER_PARAMETERS(TRACER_GLSL_MEMBER)
};

// The packed scene (core/packed_layout.h): texel i is imageLoad(packed_scene, i), an
// image rather than a usamplerBuffer for llvmpipe's sake (glsl/scene_access.glsl).
layout(binding = TRACER_PACKED_SCENE_IMAGE_UNIT, rgba32ui) uniform readonly restrict uimageBuffer packed_scene;

const float INFINITY = 1.0 / 0.0;
const float PI = 3.14159265358979;
const uint NONE = PACKED_NONE;
