// textures.glsl: images (bilinear, wrapping), procedural noise, and the texture records
// of the packed scene (core/packed_layout.h "textures", "images").

// A texture coordinate folded into [0, 1] by an image's wrap mode (IMAGE_WRAP_*).
float wrap_coordinate(float x, uint mode)
{
    if (mode == uint(IMAGE_WRAP_CLAMP))
        return clamp(x, 0.0, 1.0);
    if (mode == uint(IMAGE_WRAP_MIRROR))
        return 1.0 - abs(fract(0.5 * x) * 2.0 - 1.0);
    return fract(x);
}

// Bilinear lookup of image (index) at uv, its RGBA, folded by the image's wrap modes
// (repeat unless a glTF sampler says otherwise). Texture coordinates follow OBJ and the
// Ray Tracing books: u to the right, v UP, so v = 1 is the image's top row (images are stored top row
// first). Across the top and bottom edges the filter clamps; across the left and right
// ones it wraps when u repeats.
vec4 image_lookup_rgba(uint image, vec2 uv)
{
    uvec4 record = packed_texel(image_offset + image * uint(PACKED_IMAGE_STRIDE));
    uint first = record.x;
    int width = int(record.y), height = int(record.z);
    if (width == 0 || height == 0)
        return vec4(1.0, 0.0, 1.0, 1.0);
    uint wrap_u = record.w & 3u, wrap_v = (record.w >> uint(IMAGE_WRAP_V_SHIFT)) & 3u;
    vec2 position = vec2(wrap_coordinate(uv.x, wrap_u), 1.0 - wrap_coordinate(uv.y, wrap_v)) * vec2(width, height)
                  - 0.5;
    ivec2 corner = ivec2(floor(position));
    vec2 weight = position - vec2(corner);
    vec4 colour = vec4(0.0);
    for (int k = 0; k < 4; k++) {
        work++;
        ivec2 texel = corner + ivec2(k & 1, k >> 1);
        texel.x = wrap_u == uint(IMAGE_WRAP_REPEAT) ? (texel.x % width + width) % width : clamp(texel.x, 0, width - 1);
        texel.y = clamp(texel.y, 0, height - 1);
        float w = ((k & 1) != 0 ? weight.x : 1.0 - weight.x) * ((k >> 1) != 0 ? weight.y : 1.0 - weight.y);
        colour += w * packed_vec4(first + uint(texel.y * width + texel.x));
    }
    return colour;
}

// The same, its colour.
vec3 image_lookup(uint image, vec2 uv) { return image_lookup_rgba(image, uv).rgb; }

// Gradient noise in [-1, 1] with hashed gradients (Perlin's construction, hash instead
// of a permutation table so that no table needs uploading).
float gradient_noise(vec3 p)
{
    vec3 cell = floor(p);
    vec3 f = p - cell;
    vec3 fade = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
    float result = 0.0;
    for (int k = 0; k < 8; k++) {
        work++;
        ivec3 offset = ivec3(k & 1, (k >> 1) & 1, k >> 2);
        uvec4 h = hash4(uvec4(uvec3(ivec3(cell) + offset), 0x5eedu));
        vec3 gradient = normalize(vec3(h.xyz >> 8u) * (2.0 / 16777216.0) - 1.0 + 1e-6);
        vec3 weight = mix(1.0 - fade, fade, vec3(offset));
        result += weight.x * weight.y * weight.z * dot(gradient, f - vec3(offset));
    }
    return result;
}

float turbulence(vec3 p)
{
    float sum = 0.0, weight = 1.0;
    for (int octave = 0; octave < 7; octave++) {
        work++;
        sum += weight * abs(gradient_noise(p));
        weight *= 0.5;
        p *= 2.0;
    }
    return sum;
}

// The colour of texture (index) at a surface point: world position p, uv.
vec3 texture_value(uint texture, vec3 p, vec2 uv)
{
    // Checkers nest at most one level: their two cells are evaluated as flat textures.
    for (int level = 0; level < 2; level++) {
        work++;
        uint base = texture_offset + texture * uint(PACKED_TEXTURE_STRIDE);
        uvec4 head = packed_texel(base);
        vec4 data = packed_vec4(base + 1u);
        if (head.x == uint(TEXTURE_CONSTANT))
            return data.rgb;
        if (head.x == uint(TEXTURE_IMAGE))
            return image_lookup(head.w, uv);
        if (head.x == uint(TEXTURE_NOISE))
            return vec3(0.5 * (1.0 + gradient_noise(data.w * p)));
        if (head.x == uint(TEXTURE_TURBULENCE))
            return vec3(turbulence(data.w * p));
        if (head.x == uint(TEXTURE_MARBLE))
            return vec3(0.5 * (1.0 + sin(data.w * p.z + 10.0 * turbulence(p))));
        // Checker: the cell parity of floor(p / scale + 1/4) picks the even or the odd
        // texture. The quarter-cell offset keeps cell boundaries off the planes scenes put
        // surfaces on (a floor at y = 0, walls at whole units), where the sign of a hit
        // point's rounding would otherwise pick the cell.
        ivec3 cell = ivec3(floor(p / data.w + 0.25));
        texture = ((cell.x + cell.y + cell.z) & 1) == 0 ? head.y : head.z;
    }
    return vec3(1.0, 0.0, 1.0);
}
