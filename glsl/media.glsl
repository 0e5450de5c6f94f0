// media.glsl: volumes of constant density (instances flagged INSTANCE_VOLUME in
// core/packed_layout.h): which media a path is in, where it scatters in them, and how
// much light gets through them to a light.
//
// A path's media are two 16-bit volume instance numbers + 1 in one uint, the inner one
// low (0: none); the packer's packed_media_at computes the camera's the same way.

// The inner medium (a volume instance number + 1), 0 when the path is in none.
uint media_inner(uint media) { return media & 0xffffu; }

// The media after entering volume instance, which becomes the inner one.
uint media_enter(uint media, uint instance)
{
    return ((media & 0xffffu) << 16) | ((instance + 1u) & 0xffffu);
}

// The media after leaving volume instance.
uint media_leave(uint media, uint instance)
{
    uint number = (instance + 1u) & 0xffffu;
    if ((media & 0xffffu) == number)
        return media >> 16;
    if ((media >> 16) == number)
        return media & 0xffffu;
    return media;
}

// A medium's record (instance texel 4): (density, scattering albedo.rgb); medium is a
// volume instance number + 1, as media_inner() returns it.
vec4 medium_record(uint medium)
{
    return packed_vec4(instance_offset + (medium - 1u) * uint(PACKED_INSTANCE_STRIDE) + 4u);
}

// Whether a ray in the media scatters before the next surface at t_max: the distance to
// the event is exponential with the inner medium's density (drawn from stream 4 of
// bounce). On an event, distance and the medium's scattering albedo are set.
bool medium_scatters(uint media, float t_max, uint bounce, out float distance, out vec3 albedo)
{
    distance = INFINITY;
    albedo = vec3(1.0);
    uint medium = HAS_VOLUMES ? media_inner(media) : 0u;
    if (medium == 0u)
        return false;
    vec4 volume = medium_record(medium);
    distance = -log(1.0 - random4(bounce, 4u).x) / volume.x;
    albedo = volume.yzw;
    return distance < t_max;
}

// The isotropic phase function of every medium: its density, and a direction drawn
// from it (uniform on the sphere).
const float PHASE_PDF = 1.0 / (4.0 * PI);

vec3 sample_phase(vec2 u) { return random_unit_vector(u); }

// A shadow ray's way to its light through volume boundaries (in the variants with
// volumes): it goes on through each, losing exp(-density * length) in each medium, as
// the path itself would; at most SHADOW_CROSSINGS of them, then it is taken as blocked.
const int SHADOW_CROSSINGS = 8;

struct ShadowTransit {
    float distance;      // to the light from where the ray started
    float travelled;     // through the boundaries passed so far
    vec3 transmittance;  // through the media passed so far
    uint media;          // at the ray's origin
    int crossings;       // boundaries passed
};

ShadowTransit shadow_transit(float distance, uint media)
{
    ShadowTransit transit;
    transit.distance = distance;
    transit.travelled = 0.0;
    transit.transmittance = vec3(1.0);
    transit.media = media;
    transit.crossings = 0;
    return transit;
}

// Whether a traced shadow ray (glsl/traverse.glsl trace_rays: blocked, hit) stopped at a
// volume boundary short of its light, which it must pass (shadow_cross) to go on.
bool shadow_at_boundary(ShadowRay ray, bool blocked, Hit hit)
{
    return HAS_VOLUMES && !blocked && hit.t < ray.t_max && hit.instance != NONE;
}

// The fraction of the light that a traced shadow ray that did not stop at a boundary
// brings: none when blocked, else what the media let through, the last stretch in the
// medium it is in (to the light, or to the light's own surface when the trace met it).
vec3 shadow_arrived(ShadowTransit transit, ShadowRay ray, bool blocked, Hit hit)
{
    if (blocked)
        return vec3(0.0);
    if (!HAS_VOLUMES)
        return vec3(1.0);
    float segment = hit.t < ray.t_max ? hit.t : transit.distance - transit.travelled;
    uint medium = media_inner(transit.media);
    return medium != 0u ? transit.transmittance * exp(-medium_record(medium).x * segment) : transit.transmittance;
}

// Moves a shadow ray past the volume boundary it stopped at (hit, surface there), into or
// out of that medium, losing what the medium before it took. False when that was one
// boundary too many.
bool shadow_cross(inout ShadowRay ray, inout ShadowTransit transit, Hit hit, Surface surface)
{
    uint medium = media_inner(transit.media);
    if (medium != 0u)
        transit.transmittance *= exp(-medium_record(medium).x * hit.t);
    bool entering = dot(ray.direction, surface.geometric) < 0.0;
    transit.media = entering ? media_enter(transit.media, hit.instance) : media_leave(transit.media, hit.instance);
    float step = hit.t + ray_offset(surface.position);
    ray.origin += step * ray.direction;
    transit.travelled += step;
    // Hits within 1e-4 of the light's distance are the light itself (or beyond it).
    ray.t_max = (transit.distance - transit.travelled) * (1.0 - 1e-4);
    transit.crossings++;
    return transit.crossings < SHADOW_CROSSINGS;
}
