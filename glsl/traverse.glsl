// traverse.glsl: the nearest hit along a ray, through the two-level BVH of the packed
// scene (core/packed_layout.h "nodes", "instances").

const int STACK_SIZE = 2 * BVH_MAX_DEPTH + 2 * BVH_MAX_LEAF_SIZE;

// Finds the nearest hit closer than t_max along the ray by walking the top-level BVH and,
// through instance records, the objects' BVHs, nearer child first, with one explicit
// stack. work counts node visits and primitive tests; overflow is set when the hard cap
// cut the traversal.
//
// The loop carries the current node as the (first, count) pair of its record rather than
// its index: both children's records are fetched anyway to test their boxes, and their w
// components are those pairs, so a node is never fetched twice (4 fetches per interior
// node instead of 6). Stack entries are such pairs too, with two markers for instances:
// count ENTER_INSTANCE (first = the instance) moves the ray into the instance's object,
// count LEAVE_INSTANCE restores the world ray.
const uint ENTER_INSTANCE_MARK = 0xfffffffeu;
const uint LEAVE_INSTANCE_MARK = 0xffffffffu;

bool trace(vec3 world_origin, vec3 world_direction, float time, float t_max, out Hit hit)
{
    hit.t = t_max;
    hit.primitive = 0u;
    hit.instance = NONE;
    hit.barycentric = vec2(0.0);
    if (node_count == 0u)
        return false;
    vec3 origin = world_origin;
    vec3 direction = world_direction;
    vec3 inverse_direction = 1.0 / direction;
    uint instance = NONE;
    uvec4 root_low = packed_texel(node_offset), root_high = packed_texel(node_offset + 1u);
    float node_entry = intersect_box(packed_xyz(root_low), packed_xyz(root_high), origin, inverse_direction, t_max);
    if (node_entry == INFINITY)
        return false;
    uint first = root_low.w, count = root_high.w;

    uint stack_first[STACK_SIZE];
    uint stack_count[STACK_SIZE];
    float stack_entry[STACK_SIZE];
    int stack_size = 0;
    for (;;) {
        if (!count_work())
            break;
        if (HAS_INSTANCES && count == LEAVE_INSTANCE_MARK) {
            origin = world_origin;
            direction = world_direction;
            inverse_direction = 1.0 / direction;
            instance = NONE;
        } else if (node_entry < hit.t) {
            if (count > 0u) {
                for (uint slot = first; slot < first + count && count_work(); slot++) {
                    uvec4 record = packed_texel(primitive_offset + slot);
                    uint type = record_type(record);
                    if (HAS_INSTANCES && type == uint(PRIMITIVE_INSTANCE)) {
                        if (stack_size + 2 <= STACK_SIZE) {
                            stack_count[stack_size] = LEAVE_INSTANCE_MARK;
                            stack_entry[stack_size] = -INFINITY;
                            stack_first[stack_size + 1] = record.x;
                            stack_count[stack_size + 1] = ENTER_INSTANCE_MARK;
                            stack_entry[stack_size + 1] = -INFINITY;
                            stack_size += 2;
                        } else {
                            overflow = true;   // reported as an error, never skipped silently
                        }
                    } else {
                        intersect_primitive(slot, record, type, origin, direction, time, instance, hit);
                    }
                }
            } else {
                uint base = node_offset + first * uint(PACKED_NODE_STRIDE);
                uvec4 left_low = packed_texel(base), left_high = packed_texel(base + 1u);
                uvec4 right_low = packed_texel(base + 2u), right_high = packed_texel(base + 3u);
                float left_entry = intersect_box(packed_xyz(left_low), packed_xyz(left_high), origin,
                                                 inverse_direction, hit.t);
                float right_entry = intersect_box(packed_xyz(right_low), packed_xyz(right_high), origin,
                                                  inverse_direction, hit.t);
                bool right_nearer = right_entry < left_entry;
                uvec2 near_node = right_nearer ? uvec2(right_low.w, right_high.w) : uvec2(left_low.w, left_high.w);
                uvec2 far_node = right_nearer ? uvec2(left_low.w, left_high.w) : uvec2(right_low.w, right_high.w);
                float near_entry = min(left_entry, right_entry), far_entry = max(left_entry, right_entry);
                if (near_entry < INFINITY) {
                    if (far_entry < INFINITY) {
                        if (stack_size < STACK_SIZE) {
                            stack_first[stack_size] = far_node.x;
                            stack_count[stack_size] = far_node.y;
                            stack_entry[stack_size] = far_entry;
                            stack_size++;
                        } else {
                            overflow = true;
                        }
                    }
                    first = near_node.x;
                    count = near_node.y;
                    node_entry = near_entry;
                    continue;
                }
            }
        }
        if (stack_size == 0)
            break;
        stack_size--;
        first = stack_first[stack_size];
        count = stack_count[stack_size];
        node_entry = stack_entry[stack_size];
        if (HAS_INSTANCES && count == ENTER_INSTANCE_MARK) {
            instance = first;
            to_object(instance, world_origin, world_direction, origin, direction);
            inverse_direction = 1.0 / direction;
            uint root = node_offset + packed_texel(instance_offset + instance * uint(PACKED_INSTANCE_STRIDE)).x
                                      * uint(PACKED_NODE_STRIDE);
            uvec4 low = packed_texel(root), high = packed_texel(root + 1u);
            first = low.w;
            count = high.w;
            node_entry = intersect_box(packed_xyz(low), packed_xyz(high), origin, inverse_direction, hit.t);
        }
    }
    return hit.t < t_max;
}
