// sky.glsl: what a ray that leaves the scene sees (the sky kinds SKY_* of
// core/tracer_interface.h), and the environment map's importance sampling (its
// distribution is the packed scene's "environment" section, core/packed_layout.h).

// The sky's radiance along a world direction.
vec3 sky_radiance(vec3 direction)
{
    if (sky_kind() == SKY_CONSTANT)
        return sky_intensity * sky_bottom;
    if (sky_kind() != SKY_BOX && sky_kind() != SKY_ENVIRONMENT)
        return sky_intensity * mix(sky_bottom, sky_top, 0.5 * (direction.y + 1.0));
    // Turn the direction into the sky's own frame (the sky turns by +rotation about Y).
    float c = cos(sky_rotation), s = sin(sky_rotation);
    vec3 d = vec3(c * direction.x - s * direction.z, direction.y, s * direction.x + c * direction.z);
    if (sky_kind() == SKY_ENVIRONMENT) {
        vec2 uv = vec2(0.5 + atan(d.x, -d.z) / (2.0 * PI), 1.0 - acos(clamp(d.y, -1.0, 1.0)) / PI);
        return sky_intensity * image_lookup(sky_environment, uv);
    }
    // Cube map faces as OpenGL lays them out: major axis, then (s, t) on the face.
    vec3 a = abs(d);
    uint face_image;
    vec2 st;
    float major;
    if (a.x >= a.y && a.x >= a.z) {
        major = a.x;
        face_image = d.x > 0.0 ? sky_faces_x.x : sky_faces_x.y;
        st = d.x > 0.0 ? vec2(-d.z, -d.y) : vec2(d.z, -d.y);
    } else if (a.y >= a.z) {
        major = a.y;
        face_image = d.y > 0.0 ? sky_faces_y.x : sky_faces_y.y;
        st = d.y > 0.0 ? vec2(d.x, d.z) : vec2(d.x, -d.z);
    } else {
        major = a.z;
        face_image = d.z > 0.0 ? sky_faces_z.x : sky_faces_z.y;
        st = d.z > 0.0 ? vec2(d.x, -d.y) : vec2(-d.x, -d.y);
    }
    // (s, t) run right and down on the face image; v runs up.
    vec2 face_uv = clamp(0.5 * (st / major + 1.0), 0.00001, 0.99999);
    return sky_intensity * image_lookup(face_image, vec2(face_uv.x, 1.0 - face_uv.y));
}

// ---- environment map sampling

// Index of the first of count cumulative values (one float per texel from base) that
// exceeds u: a binary search.
uint search_cumulative(uint base, uint count, float u)
{
    uint low = 0u, high = count - 1u;
    while (low < high) {
        work++;
        uint middle = (low + high) / 2u;
        if (u < packed_vec4(base + middle).x)
            high = middle;
        else
            low = middle + 1u;
    }
    return low;
}

float cumulative_step(uint base, uint index)
{
    return packed_vec4(base + index).x - (index > 0u ? packed_vec4(base + index - 1u).x : 0.0);
}

// World direction <-> the environment image's (u, v down) coordinates, as sky_radiance
// reads them (the sky turned by sky_rotation about +Y).
vec3 environment_direction(vec2 uv)
{
    float theta = PI * uv.y, phi = 2.0 * PI * (uv.x - 0.5);
    vec3 d = vec3(sin(phi) * sin(theta), cos(theta), -cos(phi) * sin(theta));
    float c = cos(sky_rotation), s = sin(sky_rotation);
    return vec3(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
}

// Solid-angle density with which light sampling picks direction (world) from the
// environment, given the light record's image size.
float environment_pdf(uint light, vec3 direction)
{
    uvec4 head = packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE));
    uint width = head.y, height = head.z;
    float c = cos(sky_rotation), s = sin(sky_rotation);
    vec3 d = vec3(c * direction.x - s * direction.z, direction.y, s * direction.x + c * direction.z);
    vec2 uv = vec2(0.5 + atan(d.x, -d.z) / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI);
    uint column = min(uint(uv.x * float(width)), width - 1u);
    uint row = min(uint(uv.y * float(height)), height - 1u);
    float pixel = cumulative_step(environment_offset, row)
                * cumulative_step(environment_offset + height + row * width, column);
    float sine = sin(PI * (float(row) + 0.5) / float(height));
    return sine > 0.0 ? pixel * float(width * height) / (2.0 * PI * PI * sine) : 0.0;
}

// A direction towards the environment chosen in proportion to its luminance.
bool sample_environment(uint light, vec2 u, out vec3 direction, out vec3 emitted, out float pdf)
{
    uvec4 head = packed_texel(light_offset + light * uint(PACKED_LIGHT_STRIDE));
    uint width = head.y, height = head.z;
    uint row = search_cumulative(environment_offset, height, u.x);
    uint row_base = environment_offset + height + row * width;
    uint column = search_cumulative(row_base, width, u.y);
    // Reuse what is left of u inside the chosen cells for the position within the pixel.
    float row_low = row > 0u ? packed_vec4(environment_offset + row - 1u).x : 0.0;
    float column_low = column > 0u ? packed_vec4(row_base + column - 1u).x : 0.0;
    float within_row = clamp((u.x - row_low) / max(cumulative_step(environment_offset, row), 1e-20), 0.0, 1.0);
    float within_column = clamp((u.y - column_low) / max(cumulative_step(row_base, column), 1e-20), 0.0, 1.0);
    vec2 uv = vec2((float(column) + within_column) / float(width), (float(row) + within_row) / float(height));
    direction = environment_direction(uv);
    pdf = environment_pdf(light, direction);
    emitted = sky_radiance(direction);
    return pdf > 0.0;
}
