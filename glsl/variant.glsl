// variant.glsl: which parts of the tracer this program has, defined once.
//
// core/gpu_program.c (gpu_variant_defines) defines every RTSPHERES_OMIT_* as 0 or 1 from the GPU_OMIT_*
// bits of core/gpu.h, which core/render.c computes from the scene: code for what the scene
// cannot reach is left out, because llvmpipe runs both sides of every branch and so pays
// for all the code in a loop (docs/performance.md). Code that needs a feature says so with
// a plain `if (HAS_...)` where it is: these are compile-time constants, so the compiler
// drops the code behind a false one as an #if would.
const bool HAS_DIRECT_LIGHT = RTSPHERES_OMIT_DIRECT_LIGHT == 0;   // light sampling, Whitted's lights
const bool HAS_VOLUMES = RTSPHERES_OMIT_VOLUMES == 0;             // media, volume boundaries
const bool HAS_TEXTURES = RTSPHERES_OMIT_TEXTURES == 0;           // textures, normal maps, uvs
const bool HAS_SPHERES = RTSPHERES_OMIT_SPHERES == 0;             // spheres, moving or not
const bool HAS_MOVING_SPHERES = RTSPHERES_OMIT_MOVING_SPHERES == 0;
const bool HAS_TRIANGLES = RTSPHERES_OMIT_TRIANGLES == 0;
const bool HAS_QUADS = RTSPHERES_OMIT_QUADS == 0;
const bool HAS_INSTANCES = RTSPHERES_OMIT_INSTANCES == 0;         // a second BVH level
const bool HAS_EMITTERS = RTSPHERES_OMIT_EMITTERS == 0;           // emissive materials
const bool HAS_LIGHT_CHOICE = RTSPHERES_OMIT_LIGHT_CHOICE == 0;   // lights chosen by the point
const bool HAS_RECTANGLE_LIGHTS = RTSPHERES_OMIT_RECTANGLE_LIGHTS == 0;   // quad lights (rectangles by solid angle)
const bool HAS_PBR = RTSPHERES_OMIT_PBR == 0;                     // the pbr material
const bool HAS_ALPHA_MASK = RTSPHERES_OMIT_ALPHA_MASK == 0;       // alpha-masked materials
const bool HAS_VERTEX_COLORS = RTSPHERES_OMIT_VERTEX_COLORS == 0; // the vertex colour section
const bool HAS_LIGHT_GROUPS = RTSPHERES_OMIT_LIGHT_GROUPS == 0;   // light group layers
const bool HAS_DIRECT_EMISSION = RTSPHERES_OMIT_DIRECT_EMISSION == 0;   // the denoiser's direct emission sums
const bool HAS_SQUARES = RTSPHERES_OMIT_SQUARES == 0;   // the sums of squares' state texture (--variance)
const bool HAS_STACK_WALK = RTSPHERES_OMIT_STACK_WALK == 0;   // the nodes walked with a stack (else the threaded lists)
const bool HAS_SPHERE_LIGHTS = RTSPHERES_OMIT_SPHERE_LIGHTS == 0;     // emissive spheres
const bool HAS_TRIANGLE_LIGHTS = RTSPHERES_OMIT_TRIANGLE_LIGHTS == 0; // emissive triangles
const bool HAS_DELTA_LIGHTS = RTSPHERES_OMIT_DELTA_LIGHTS == 0;       // point, spot and sun lights
const bool HAS_ENVIRONMENT_LIGHT = RTSPHERES_OMIT_ENVIRONMENT_LIGHT == 0;   // the sky sampled as a light
const bool HAS_MANY_LIGHTS = RTSPHERES_OMIT_MANY_LIGHTS == 0;         // more than one light to choose from
const bool HAS_LIGHT_TREE = RTSPHERES_OMIT_LIGHT_TREE == 0;           // lights chosen by walking the light tree
const bool HAS_LAMBERTIAN = RTSPHERES_OMIT_LAMBERTIAN == 0;           // material kinds
const bool HAS_METAL = RTSPHERES_OMIT_METAL == 0;
const bool HAS_DIELECTRIC = RTSPHERES_OMIT_DIELECTRIC == 0;

// Derived: flat primitives (triangles, quads), and scenes of a single primitive kind, whose
// records need no type test.
const bool HAS_FLAT = HAS_TRIANGLES || HAS_QUADS;
const bool HAS_FLAT_LIGHTS = HAS_RECTANGLE_LIGHTS || HAS_TRIANGLE_LIGHTS;   // quad and triangle lights
const bool HAS_AREA_LIGHTS = HAS_SPHERE_LIGHTS || HAS_FLAT_LIGHTS;
const bool ONLY_SPHERES = !HAS_TRIANGLES && !HAS_QUADS && !HAS_MOVING_SPHERES && !HAS_INSTANCES;
const bool ONLY_TRIANGLES = !HAS_SPHERES && !HAS_QUADS && !HAS_INSTANCES;
const bool ONLY_QUADS = !HAS_SPHERES && !HAS_TRIANGLES && !HAS_INSTANCES;
// The packer writes the threaded walk only for still spheres and quads in one level, and
// core/render.c asks for it only without alpha masks (the stack's walk tests them); the
// conditions here say the same, so that no other variant compiles it.
const bool THREADED_WALK = !HAS_STACK_WALK && !HAS_TRIANGLES && !HAS_MOVING_SPHERES && !HAS_INSTANCES
                           && !HAS_ALPHA_MASK;

// The integrator, the sky kind and the sampler: compiled in as constants (RTSPHERES_FIX_UNIFORMS 1,
// gpu.h GPU_FIX_UNIFORMS), or read from the parameter block (the full tracer).
const bool FIXED_SETTINGS = RTSPHERES_FIX_UNIFORMS != 0;

int tracer_integrator() { return FIXED_SETTINGS ? RTSPHERES_INTEGRATOR : integrator; }
int sky_kind() { return FIXED_SETTINGS ? RTSPHERES_SKY_TYPE : sky_type; }
int sampler_kind() { return FIXED_SETTINGS ? RTSPHERES_SAMPLER : sampler; }
