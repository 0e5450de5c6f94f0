// traverse.glsl: the BVH walk of the packed scene (core/packed_layout.h "nodes",
// "instances"): the nearest hit of a path ray and whether a shadow ray gets through, both
// in ONE loop. GLSL inlines every call, and llvmpipe runs all of a loop's code on every
// iteration of it (docs/performance.md): a second traversal loop for shadow rays would
// be paid in full on every segment, so the segment loop (glsl/integrators.glsl) hands
// each trace its path ray and the shadow ray it has pending, and this one loop walks one
// after the other.

const int STACK_SIZE = 2 * BVH_MAX_DEPTH + 2 * BVH_MAX_LEAF_SIZE;

// The loop carries the current item as the (first, count) pair of its node record rather
// than its index: both children's records are fetched anyway to test their boxes, and
// their w components are those pairs, so a node is never fetched twice (4 fetches per
// interior node instead of 6). A stack entry is such a pair in one word, count in the top
// bits (a leaf holds at most BVH_MAX_LEAF_SIZE primitives; the packer keeps first below
// 2^PACKED_FIRST_BITS), and nothing else: llvmpipe writes and reads a per-lane array index
// one lane at a time, and a store as a read, a per-lane branch on the lane's mask and a
// write, so the stack is one array, written at the loop's top level (see trace_rays;
// only an instance's two marks are pushed inside a condition, and only by variants with
// instances). A popped entry carries no entry distance to cull it by: its children's
// boxes (or a leaf's primitives) are tested against the nearest hit in its own iteration,
// which costs less than the second array did (docs/performance.md, the log).
// Two counts mark instances:
// ENTER_INSTANCE (first = the instance) moves the ray into the instance's object and
// goes on at its root, LEAVE_INSTANCE restores the world ray. Entering is an iteration of
// its own whose four texels (the instance's head and matrix) are fetched by the same
// calls as an interior node's four: llvmpipe pays for every fetch call in the loop on
// every iteration, wanted or not.
const uint STACK_FIRST_BITS = uint(PACKED_FIRST_BITS);
const uint STACK_FIRST_MASK = (1u << STACK_FIRST_BITS) - 1u;
const uint ENTER_INSTANCE_MARK = 6u;
const uint LEAVE_INSTANCE_MARK = 7u;

uint stack_word(uint first, uint count) { return first | (count << STACK_FIRST_BITS); }

// With triangles, a leaf primitive is read by the loop's four node fetches, in an
// iteration of its own (a leaf found going down is tested in the next iteration), rather
// than by fetches of its own in every iteration: an iteration then makes 4 fetches (the
// record and the three vertices, or a node pair) instead of 8. Measured
// (docs/performance.md, the log): meshes of 82k and 1.3M triangles 10 and 20% faster, but
// the Cornell box (quads) no faster and lights.txt (quads and spheres) 5% slower, where
// the extra iteration per leaf costs more than the fetches save; a sphere is its record
// alone. So only the variants with triangles do it.
const bool LEAF_TEXELS = HAS_TRIANGLES;

// A leaf primitive's record as the traversal needs it. With quads alone in one BVH level,
// quad k's shape record is at shape_offset + 3k (core/packed_layout.h, "primitives"; the
// packer writes them in slot order), so its record is known from its slot and the quad's
// three texels are fetched without waiting for the record: 7 fetches an iteration instead
// of 8, in a chain of two instead of three (Cornell box -9%, docs/performance.md, the log).
uvec4 leaf_record(uint slot)
{
    if (ONLY_QUADS)
        return uvec4(shape_offset + uint(PACKED_QUAD_TEXELS) * slot, 0u, 0u,
                     PRIMITIVE_RECORD_TAG + uint(PRIMITIVE_QUAD));
    return packed_texel(primitive_offset + slot);
}

// A shadow ray: from origin towards a light, which it reaches at t_max (just short of
// the light, so that the light itself is not in the way).
struct ShadowRay {
    vec3 origin;
    vec3 direction;
    float t_max;
    uint light_slot;   // the area light's world primitive, not a blocker; NONE for others
    float time;
};

// No hit closer than t_max.
Hit no_hit(float t_max)
{
    Hit hit;
    hit.t = t_max;
    hit.primitive = 0u;
    hit.instance = NONE;
    hit.barycentric = vec2(0.0);
    return hit;
}

// Texels a threaded walk's item takes: a quad's three, else two (core/packed_layout.h).
const uint THREADED_STRIDE = uint(HAS_QUADS ? PACKED_THREADED_QUAD_ITEM_STRIDE : PACKED_THREADED_ITEM_STRIDE);

// The first texel of the threaded walk's list for ray: its octant's, by the signs of its
// inverse direction, which its boxes' corners are ordered for (core/packed_layout.h).
uint threaded_list(TraversalRay ray)
{
    vec3 inverse = ray.inverse_direction;
    uint octant = (inverse.x < 0.0 ? 1u : 0u) | (inverse.y < 0.0 ? 2u : 0u) | (inverse.z < 0.0 ? 4u : 0u);
    return threaded_offset + octant * threaded_items * THREADED_STRIDE;
}

// One item of the threaded walk (core/packed_layout.h "threaded walk") of the list at
// list: its box and its primitive tests all run (llvmpipe runs every branch anyway,
// docs/performance.md), a sphere or quad nearer than hit made the hit (primitive_hit
// true). Returns the next item: the one after a primitive or a box hit, the item's skip
// after a box missed.
uint threaded_step(TraversalRay ray, uint list, uint item, inout Hit hit, out bool primitive_hit)
{
    uint base = list + item * THREADED_STRIDE;
    uvec4 first_texel = packed_texel(base), second_texel = packed_texel(base + 1u);
    uvec4 third_texel = HAS_QUADS ? packed_texel(base + 2u) : uvec4(0u);
    bool sphere = HAS_SPHERES && (second_texel.w & THREADED_SPHERE) != 0u;
    bool quad = HAS_QUADS && (second_texel.w & THREADED_QUAD) != 0u;
    float box_entry = intersect_ordered_box(packed_xyz(first_texel), packed_xyz(second_texel), ray.origin,
                                            ray.inverse_direction, hit.t);
    float t = INFINITY;
    vec2 coordinates = vec2(0.0);
    if (HAS_SPHERES)
        t = intersect_sphere_along(packed_xyz(first_texel), uintBitsToFloat(second_texel.x), ray.origin, ray.unit,
                                   ray.inverse_length, hit.t);
    if (HAS_QUADS) {
        vec2 quad_coordinates;
        float quad_t = intersect_flat(packed_xyz(first_texel), packed_xyz(second_texel), packed_xyz(third_texel), true,
                                      ray.origin, ray.direction, hit.t, quad_coordinates);
        t = quad ? quad_t : sphere ? t : INFINITY;
        coordinates = quad ? quad_coordinates : vec2(0.0);
    } else {
        t = sphere ? t : INFINITY;
    }
    primitive_hit = t < hit.t;
    if (primitive_hit) {
        hit.t = t;
        hit.primitive = second_texel.w & THREADED_SLOT_MASK;
        hit.barycentric = coordinates;
    }
    return sphere || quad || box_entry < INFINITY ? item + 1u : first_texel.w;
}

// trace_rays for the variants with the threaded walk (THREADED_WALK: still spheres and
// quads in one level): the shadow ray, then the path ray, each along the list of its
// octant (threaded_list), one item an iteration (threaded_step). No stack: an iteration
// is two or three fetches at one address and the tests, where the stack's walk makes four
// fetches in a chain, two box tests, a primitive test and a per-lane stack write and read.
// Two loops, unlike the stack's walk: this loop is short, and one loop for both rays
// (changing rays inside it) was 5% slower on a lit scene than the stack's walk, two loops
// 20% faster (docs/performance.md, the log).
void trace_threaded(bool shadow_wanted, ShadowRay shadow, bool path_wanted, vec3 path_origin, vec3 path_direction,
                    float path_t_max, out bool blocked, out Hit shadow_hit, out Hit path_hit)
{
    blocked = false;
    shadow_hit = no_hit(shadow.t_max);
    path_hit = no_hit(path_t_max);
    bool primitive_hit;
    // Without light sampling there is never a shadow ray: a constant, so that its loop
    // is left out.
    if (HAS_DIRECT_LIGHT && shadow_wanted) {
        TraversalRay ray = traversal_ray(shadow.origin, shadow.direction);
        uint list = threaded_list(ray);
        uint item = 0u;
        while (count_work()) {
            item = threaded_step(ray, list, item, shadow_hit, primitive_hit);
            // A shadow ray's blocker: any primitive but its light.
            blocked = primitive_hit && shadow_hit.primitive != shadow.light_slot;
            if (item >= threaded_items || blocked)
                break;
        }
    }
    if (path_wanted) {
        TraversalRay ray = traversal_ray(path_origin, path_direction);
        uint list = threaded_list(ray);
        uint item = 0u;
        while (count_work()) {
            item = threaded_step(ray, list, item, path_hit, primitive_hit);
            if (item >= threaded_items)
                break;
        }
    }
}

// Walks the shadow ray (when shadow_wanted) and then the path ray (when path_wanted)
// through the top-level BVH and, through instance records, the objects' BVHs, nearer
// child first, with one explicit stack. The path ray gets its nearest hit closer than
// path_t_max in path_hit (t = path_t_max: none). The shadow ray stops at the first
// blocker (blocked); what else it hits is not in the way: the light (light_slot) and, in
// the variants with volumes, the boundaries of volume instances, the nearest of which
// comes back in shadow_hit (t = its t_max: none) for the caller to step through
// (glsl/media.glsl). work counts node visits and primitive tests; overflow is set when the
// hard cap cut the walk.
void trace_rays(bool shadow_wanted, ShadowRay shadow, bool path_wanted, vec3 path_origin, vec3 path_direction,
                float path_time, float path_t_max, out bool blocked, out Hit shadow_hit, out Hit path_hit)
{
    blocked = false;
    shadow_hit = no_hit(shadow.t_max);
    path_hit = no_hit(path_t_max);
    if (node_count == 0u || !(shadow_wanted || path_wanted))
        return;
    if (THREADED_WALK) {
        trace_threaded(shadow_wanted, shadow, path_wanted, path_origin, path_direction, path_t_max, blocked,
                       shadow_hit, path_hit);
        return;
    }
    TraversalRay shadow_world = traversal_ray(shadow.origin, shadow.direction);
    TraversalRay path_world = traversal_ray(path_origin, path_direction);
    uvec4 root_low = packed_texel(node_offset), root_high = packed_texel(node_offset + 1u);

    bool shadow_phase = shadow_wanted;   // false: the path ray's turn
    TraversalRay world = shadow_phase ? shadow_world : path_world;
    TraversalRay ray = world;
    float time = shadow_phase ? shadow.time : path_time;
    Hit hit = shadow_phase ? shadow_hit : path_hit;
    uint instance = NONE;
    bool volume_instance = false;
    // The root's box is not tested: its children's are, in the first iteration.
    uint first = root_low.w, count = root_high.w;
    bool stop = false;   // the shadow ray is blocked
    // One slot more than the stack can hold: every iteration writes the free slot above
    // the top (below), also when the stack is full.
    uint stack[STACK_SIZE + 1];
    int stack_size = 0;
    for (;;) {
        if (!count_work())
            break;
        bool entering = HAS_INSTANCES && count == ENTER_INSTANCE_MARK;
        // The iteration's four texels: an interior node's pair of children, an instance's
        // head and matrix, or (LEAF_TEXELS) a leaf primitive's record and the three texels
        // behind it, all by the same four fetch calls.
        bool at_leaf = LEAF_TEXELS && count != 0u && !entering && !(HAS_INSTANCES && count == LEAVE_INSTANCE_MARK);
        uint base = entering ? instance_offset + first * uint(PACKED_INSTANCE_STRIDE)
                  : at_leaf  ? primitive_offset + first
                             : node_offset + first * uint(PACKED_NODE_STRIDE);
        uvec4 texel0 = packed_texel(base);
        uvec3 behind = uvec3(base + 1u, base + 2u, base + 3u);
        if (at_leaf)
            behind = primitive_geometry_addresses(texel0, record_type(texel0));
        uvec4 texel1 = packed_texel(behind.x), texel2 = packed_texel(behind.y), texel3 = packed_texel(behind.z);
        // An interior node's children's boxes, the nearer one to go on with and the farther
        // one written to the free slot above the stack's top, in every iteration whatever
        // its item (llvmpipe would run this code in every iteration anyway). A push is then
        // only stack_size++. Here, outside every condition, the store's per-lane branch
        // follows whether the lane is still walking; inside the push's condition it went
        // either way at random (docs/performance.md, the log).
        float left_entry = intersect_box(packed_xyz(texel0), packed_xyz(texel1), ray.origin, ray.inverse_direction,
                                         hit.t);
        float right_entry = intersect_box(packed_xyz(texel2), packed_xyz(texel3), ray.origin, ray.inverse_direction,
                                          hit.t);
        bool right_nearer = right_entry < left_entry;
        uvec2 near_node = right_nearer ? uvec2(texel2.w, texel3.w) : uvec2(texel0.w, texel1.w);
        uvec2 far_node = right_nearer ? uvec2(texel0.w, texel1.w) : uvec2(texel2.w, texel3.w);
        bool near_hit = min(left_entry, right_entry) < INFINITY, far_hit = max(left_entry, right_entry) < INFINITY;
        stack[stack_size] = stack_word(far_node.x, far_node.y);
        if (HAS_INSTANCES && count == LEAVE_INSTANCE_MARK) {
            ray = world;
            instance = NONE;
            volume_instance = false;
        } else if (entering) {
            // texel0: the object's root pair and the instance's flags; 1-3: world-to-object.
            instance = first;
            volume_instance = (texel0.z & uint(INSTANCE_VOLUME)) != 0u;
            vec3 object_origin, object_direction;
            apply_world_to_object(uintBitsToFloat(texel1), uintBitsToFloat(texel2), uintBitsToFloat(texel3),
                                  world.origin, world.direction, object_origin, object_direction);
            ray = traversal_ray(object_origin, object_direction);
            first = texel0.x;
            count = texel0.w;
            continue;
        } else {
            // An interior node: the farther child hit is pushed (written above), the nearer
            // one goes next. When that one is a leaf its first primitive is tested in this
            // same iteration (below): llvmpipe runs the primitive test's code in every
            // iteration anyway (with LEAF_TEXELS, in the next: its texels come through the
            // node fetches).
            bool descend = false;
            if (count == 0u && near_hit) {
                if (far_hit) {
                    if (stack_size < STACK_SIZE)
                        stack_size++;
                    else
                        overflow = true;
                }
                first = near_node.x;
                count = near_node.y;
                descend = LEAF_TEXELS || count == 0u;
            }
            if (descend)
                continue;
            // A leaf: popped, or the nearer child just found (a node whose children both
            // missed still has count 0 here, and goes on to the pop). One primitive per
            // iteration, the rest of the leaf in the next ones, not a loop of its own:
            // llvmpipe runs an inner loop until its slowest lane is done and at least once
            // in every iteration, while here a lane with primitives left tests them as the
            // others go on walking (docs/performance.md, the log: -5 to -15% on spheres and
            // meshes). The count stays below the instance marks (BVH_MAX_LEAF_SIZE 4).
            if (count > 0u) {
                uint slot = first;
                uvec4 record = LEAF_TEXELS ? texel0 : leaf_record(slot);
                uint type = record_type(record);
                if (HAS_INSTANCES && type == uint(PRIMITIVE_INSTANCE)) {
                    if (stack_size + 2 <= STACK_SIZE) {
                        stack[stack_size] = stack_word(0u, LEAVE_INSTANCE_MARK);
                        stack[stack_size + 1] = stack_word(record.x, ENTER_INSTANCE_MARK);
                        stack_size += 2;
                    } else {
                        overflow = true;   // reported as an error, never skipped silently
                    }
                } else {
                    float before = hit.t;
                    uvec4 g0 = texel1, g1 = texel2, g2 = texel3;
                    if (!LEAF_TEXELS)
                        primitive_geometry_texels(record, type, g0, g1, g2);
                    intersect_primitive(slot, record, type, g0, g1, g2, ray, time, instance, hit);
                    // A shadow ray's blocker: anything but its light and volume boundaries.
                    bool passable = instance == NONE ? slot == shadow.light_slot : HAS_VOLUMES && volume_instance;
                    if (shadow_phase && hit.t < before && !passable)
                        stop = true;
                }
                first++;
                count--;
                if (count > 0u && !stop)
                    continue;
            }
        }
        if (stack_size == 0 || stop) {
            // This ray is done: the path ray's turn, or the end.
            if (!shadow_phase) {
                path_hit = hit;
                break;
            }
            shadow_hit = hit;
            blocked = stop;
            if (!path_wanted)
                break;
            shadow_phase = false;
            world = path_world;
            ray = world;
            time = path_time;
            hit = path_hit;
            instance = NONE;
            volume_instance = false;
            stop = false;
            first = root_low.w;
            count = root_high.w;
            stack_size = 0;
            continue;
        }
        stack_size--;
        uint word = stack[stack_size];
        first = word & STACK_FIRST_MASK;
        count = word >> STACK_FIRST_BITS;
    }
}

// The nearest hit closer than t_max along a ray (no shadow ray). True when there is one.
bool trace(vec3 origin, vec3 direction, float time, float t_max, out Hit hit)
{
    ShadowRay none;
    none.origin = origin;
    none.direction = direction;
    none.t_max = 0.0;
    none.light_slot = NONE;
    none.time = time;
    bool blocked;
    Hit shadow_hit;
    trace_rays(false, none, true, origin, direction, time, t_max, blocked, shadow_hit, hit);
    return hit.t < t_max;
}
