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

// The fraction of light that gets from p to the light primitive at distance along
// direction: 0 behind an opaque surface; through volume boundaries it goes on, losing
// exp(-density * length) in each medium, as the path itself would.
vec3 shadow_transmittance(vec3 p, vec3 direction, float distance, uint light_slot, uint media, float time)
{
    if (!HAS_VOLUMES) {
        // No medium anywhere: every surface in the way is opaque.
        Hit blocker;
        bool blocked = trace(p, direction, time, distance * (1.0 - 1e-4), blocker);
        return blocked && !(blocker.instance == NONE && blocker.primitive == light_slot) ? vec3(0.0) : vec3(1.0);
    }
    vec3 transmittance = vec3(1.0);
    float travelled = 0.0;
    vec3 origin = p;
    for (int crossing = 0; crossing < 8; crossing++) {
        work++;
        Hit hit;
        float remaining = distance - travelled;
        // Hits within 1e-4 of the light's distance are the light itself (or beyond it):
        // the traversal need not look that far.
        bool any = trace(origin, direction, time, remaining * (1.0 - 1e-4), hit);
        float segment = any ? hit.t : remaining;
        uint medium = media_inner(media);
        if (medium != 0u)
            transmittance *= exp(-medium_record(medium).x * segment);
        if (!any || (hit.instance == NONE && hit.primitive == light_slot))
            return transmittance;
        if (hit.instance == NONE)
            return vec3(0.0);
        uint instance_base = instance_offset + hit.instance * uint(PACKED_INSTANCE_STRIDE);
        if ((packed_texel(instance_base).z & uint(INSTANCE_VOLUME)) == 0u)
            return vec3(0.0);
        Surface surface = surface_at(hit, origin, direction, time);
        bool entering = dot(direction, surface.geometric) < 0.0;
        media = entering ? media_enter(media, hit.instance) : media_leave(media, hit.instance);
        float step = hit.t + ray_offset(surface.position);
        origin += step * direction;
        travelled += step;
    }
    return vec3(0.0);
}
