// camera.glsl: which pixel this invocation renders, and its camera rays (the thin lens of
// core/camera.h).

vec2 film_pixel;     // the pixel's bottom-left corner on the film (row 0 at the bottom)
ivec2 frame_pixel;   // the pixel in the traced region's framebuffer (row 0 at the bottom):
                     // gl_FragCoord, or in compacted passes what the pixel map says (main.glsl)

// Sets the pixel's film position and random stream from frame_pixel: a crop or tile
// renders exactly the pixels (and random numbers) of the full render, so both use
// full-image pixels, rows counted from the top.
void begin_pixel()
{
    ivec2 frag_pixel = frame_pixel;
    ivec2 image_pixel = ivec2(region_origin.x + frag_pixel.x, region_origin.y + (image_size.y - 1 - frag_pixel.y));
    film_pixel = vec2(float(image_pixel.x), float(full_size.y - 1 - image_pixel.y));
    rng_pixel = uvec2(image_pixel);
    rng_seed_hash = random_seed_hash(seed);
    begin_pixel_streams();
}

// The current sample's camera ray: through a jittered point of the pixel, from a random
// point of the lens (thin-lens defocus).
void camera_ray(out vec3 origin, out vec3 direction)
{
    vec4 u = random4_seeded(camera_stream_seeds);
    vec2 film = (film_pixel + u.xy) / vec2(full_size);
    vec2 lens = lens_radius * random_in_unit_disk(u.zw);
    origin = camera_origin + lens.x * camera_u + lens.y * camera_v;
    direction = normalize(camera_lower_left + film.x * camera_horizontal + film.y * camera_vertical - origin);
}

// The current sample's moment within the shutter: the same for all its segments.
float ray_time()
{
    return mix(shutter_open, shutter_close, random4_seeded(time_stream_seeds).x);
}
