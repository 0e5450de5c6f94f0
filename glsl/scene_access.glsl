// scene_access.glsl: reading the packed scene (core/packed_layout.h): texels, the
// header's section offsets, primitive records and vertices.

// Texel index of the packed scene. An image load: llvmpipe inlines it as a bounds check and
// eight loads, where a buffer texture's texelFetch is a call to its sampling routine, around
// which every vector register live in the loop is saved and restored (the traversal loop
// made 4 such calls an iteration). 4 to 12% less time a sample on most scenes, images
// identical (docs/performance.md, the log).
uvec4 packed_texel(uint index)
{
    return imageLoad(packed_scene, int(index));
}

vec3 packed_xyz(uvec4 texel) { return uintBitsToFloat(texel.xyz); }
vec4 packed_vec4(uint index) { return uintBitsToFloat(packed_texel(index)); }

// The header's offsets and counts, read once per invocation by read_header().
uint material_offset;
uint primitive_offset;
uint node_offset;
uint node_count;
uint instance_offset;
uint info_offset;
uint shape_offset;
uint vertex_offset;
uint uv_offset;
uint area_light_count;
uint default_material;
uint texture_offset;
uint image_offset;
uint light_offset;
uint light_count;    // the scene's lights; an integrator narrows it to what it samples
uint environment_offset;
uint color_offset;   // the vertex colour section, NONE when there is none
uint light_tree_offset;   // the light tree, NONE when there is none
uint threaded_offset, threaded_items;   // the threaded walk's lists (glsl/traverse.glsl trace_threaded)

// Reads the packed scene's header (packed_layout.h "header") into the globals above.
void read_header()
{
    uvec4 header0 = packed_texel(0u), header1 = packed_texel(1u), header2 = packed_texel(2u),
          header3 = packed_texel(3u), header4 = packed_texel(4u), header5 = packed_texel(5u);
    material_offset = header0.z;
    primitive_offset = header1.x;
    node_offset = header1.z;
    node_count = header1.w;
    instance_offset = header2.x;
    info_offset = header2.z;
    default_material = header2.w;
    texture_offset = header3.x;
    image_offset = header3.z;
    light_offset = header4.x;
    light_count = header4.y;
    environment_offset = header4.z;
    area_light_count = header4.w;
    shape_offset = header5.x;
    vertex_offset = header5.y;
    uv_offset = header5.z;
    uvec4 header6 = packed_texel(6u);
    color_offset = HAS_VERTEX_COLORS ? header6.x : NONE;
    light_tree_offset = HAS_LIGHT_TREE ? header6.y : NONE;
    threaded_offset = header6.z;
    threaded_items = header6.w;
}

// A vertex normal from its octahedral encoding (core/pack.h packed_encode_normal).
vec3 decode_normal(uint bits)
{
    vec2 f = unpackSnorm2x16(bits);
    vec3 n = vec3(f, 1.0 - abs(f.x) - abs(f.y));
    float t = max(-n.z, 0.0);
    n.x += n.x >= 0.0 ? -t : t;
    n.y += n.y >= 0.0 ? -t : t;
    return normalize(n);
}

// The info word of a primitive: type tag, uvs flag, material.
uint primitive_info(uint slot)
{
    return packed_texel(info_offset + slot / 4u)[slot % 4u];
}

uint primitive_type(uint info) { return info >> uint(PRIMITIVE_INFO_TYPE_SHIFT); }

// The type of a primitive from its record (packed_layout.h: every record but a sphere's
// has a tag in w), known at compile time in the variants with one kind of primitive.
uint record_type(uvec4 record)
{
    uint tagged = record.w >= PRIMITIVE_RECORD_TAG ? record.w - PRIMITIVE_RECORD_TAG : uint(PRIMITIVE_SPHERE);
    return ONLY_SPHERES ? uint(PRIMITIVE_SPHERE) : ONLY_TRIANGLES ? uint(PRIMITIVE_TRIANGLE) : tagged;
}

// The texels behind a primitive's record (a triangle's three vertices; a quad's or moving
// sphere's shape record): texel 0 (unused) for spheres and instances.
uvec3 primitive_geometry_addresses(uvec4 record, uint type)
{
    bool triangle = type == uint(PRIMITIVE_TRIANGLE);
    bool behind = type != uint(PRIMITIVE_SPHERE) && type != uint(PRIMITIVE_INSTANCE);
    uvec3 address = triangle ? uvec3(vertex_offset) + record.xyz : uvec3(record.x, record.x + 1u, record.x + 2u);
    return behind ? address : uvec3(0u);
}

// A primitive's geometry from its record and the texels behind it (g0..g2, fetched from
// primitive_geometry_addresses): sphere (centre, radius) in a; moving sphere (centre at
// time 0, radius) in a, (centre at time 1) in b; triangle and quad: corner in a, edges in
// b and c; for a triangle, normal_words are its vertices' encoded normals.
void primitive_geometry_of(uvec4 record, uint type, uvec4 g0, uvec4 g1, uvec4 g2, out vec4 a, out vec4 b,
                           out vec4 c, out uvec3 normal_words)
{
    a = uintBitsToFloat(record);
    b = vec4(0.0);
    c = vec4(0.0);
    normal_words = uvec3(VERTEX_NO_NORMAL);
    if (!ONLY_SPHERES) {
        bool triangle = type == uint(PRIMITIVE_TRIANGLE);
        bool behind = type != uint(PRIMITIVE_SPHERE) && type != uint(PRIMITIVE_INSTANCE);
        if (behind) {
            vec4 f0 = uintBitsToFloat(g0), f1 = uintBitsToFloat(g1), f2 = uintBitsToFloat(g2);
            a = triangle ? vec4(f0.xyz, 0.0) : f0;
            b = triangle ? vec4(f1.xyz - f0.xyz, 0.0) : f1;
            c = triangle ? vec4(f2.xyz - f0.xyz, 0.0) : f2;
            if (triangle)
                normal_words = uvec3(g0.w, g1.w, g2.w);
        }
    }
}

// Fetches the texels behind a primitive's record (primitive_geometry_addresses), in one
// place for every type: llvmpipe runs every branch, so per-type fetches would all be paid.
void primitive_geometry_texels(uvec4 record, uint type, out uvec4 g0, out uvec4 g1, out uvec4 g2)
{
    g0 = uvec4(0u);
    g1 = uvec4(0u);
    g2 = uvec4(0u);
    if (!ONLY_SPHERES) {
        uvec3 address = primitive_geometry_addresses(record, type);
        g0 = packed_texel(address.x);
        g1 = packed_texel(address.y);
        g2 = HAS_FLAT ? packed_texel(address.z) : uvec4(0u);   // moving spheres have 2 texels
    }
}

// A primitive's geometry (primitive_geometry_of) with the texels behind its record
// fetched here.
void primitive_geometry(uvec4 record, uint type, out vec4 a, out vec4 b, out vec4 c, out uvec3 normal_words)
{
    uvec4 g0, g1, g2;
    primitive_geometry_texels(record, type, g0, g1, g2);
    primitive_geometry_of(record, type, g0, g1, g2, a, b, c, normal_words);
}

// The vertex normals of a triangle whose vertex texels' w are bits (false when a vertex
// has none: then it is shaded flat).
bool vertex_normals(uvec3 bits, out vec3 n0, out vec3 n1, out vec3 n2)
{
    n0 = decode_normal(bits.x);
    n1 = decode_normal(bits.y);
    n2 = decode_normal(bits.z);
    return all(notEqual(bits, uvec3(VERTEX_NO_NORMAL)));
}

vec2 vertex_uv(uint vertex)
{
    uvec4 texel = packed_texel(uv_offset + vertex / 2u);
    return uintBitsToFloat((vertex & 1u) == 0u ? texel.xy : texel.zw);
}

// A vertex's colour (packed_layout.h "colours"); the caller checks color_offset != NONE.
vec3 vertex_color(uint vertex)
{
    uvec4 texel = packed_texel(color_offset + vertex / 2u);
    uvec2 words = (vertex & 1u) == 0u ? texel.xy : texel.zw;
    return vec3(unpackUnorm2x16(words.x), unpackUnorm2x16(words.y).x);
}

// The texture coordinates of a point on a sphere with unit (object-space) normal n:
// longitude and latitude as the books map spheres: u around +Y starting at -X, v from 0
// at the bottom to 1 at the top.
vec2 sphere_uv(vec3 n)
{
    return vec2(0.5 + atan(-n.z, n.x) / (2.0 * PI), acos(clamp(-n.y, -1.0, 1.0)) / PI);
}
