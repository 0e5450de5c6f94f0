"""render.py: renders one of the bench's rtspheres scenes in Blender Cycles, for `make
bench` (tests/bench/run.sh): the peer a user would pick instead of rtspheres (issue 13).

    blender -b --factory-startup -noaudio --python-exit-code 1 -P tests/bench/cycles/render.py -- \\
        SCENE -o OUT.exr [--size WxH] [--spp N] [--max-depth N] [--seed N] [--threads N]

SCENE is read by tests/bench/scene_reader.py (not rtspheres' parser: a yardstick shares no
code with what it measures), so only scenes/weekend.txt, cornell.txt and three-balls.txt
and others made of the same statements work. --size, --spp, --max-depth and --seed
override the scene's `render` line as they do for `rtspheres render`. OUT is a linear
float EXR (R, G, B, A).

Prints one line to stdout when done:
    cycles: SCENE WxH N spp in R s (render call), scene built in B s, Blender 3.4.1
R is bpy.ops.render.render() alone: Cycles' scene sync (its BVH build and shader set-up
included) and the path tracing, like rtspheres' own "render s" (BVH build to last pass).
Blender's start-up, this script's scene building and the image write are not in it; the
bench times the whole process too.

The same scene, as near as two renderers allow (what differs is said where it is set):
- Coordinates: rtspheres' y is up, Blender's z: (x, y, z) -> (x, -z, y), a rotation.
- Spheres are Cycles point-cloud points, which Cycles intersects as analytic spheres:
  one point cloud per material type (Mesh to Points in geometry nodes), each sphere's
  colour, metal roughness and IOR as point attributes read by the shader, since Cycles
  gives every point of a cloud its first material. Quads and boxes are one mesh of
  quads with a material per face.
- lambertian -> Diffuse BSDF (roughness 0, Lambert); metal -> Glossy BSDF, GGX (see
  metal_roughness: the lobes differ); dielectric -> Glass BSDF, sharp (exact Fresnel
  where rtspheres uses Schlick's approximation); emissive surfaces -> Emission (Cycles'
  mesh lights emit from both sides, as rtspheres' emitters do); an emissive sphere -> a
  point light of that radius (see sphere_light).
- Sky: the world shader, gradient or constant as rtspheres blends it, not
  importance-sampled (rtspheres does not sample a gradient or constant sky as a light).
- Camera: same position, vertical field of view, aspect; a thin lens of the same
  diameter and focus distance (round aperture).
- Sampling: CPU, the given threads, box pixel filter 1 px wide (rtspheres jitters
  uniformly in the pixel), adaptive sampling off, denoising off, no clamping, no glossy
  filter, Cycles' default sampling pattern and light threshold (Blender 3.4 has no light
  tree). Bounces: rtspheres' depth counts path segments, Cycles' max bounces count
  scatterings after the first hit, so Cycles gets depth - 1 (depth 1 is direct light
  only in both), in every bounce category.
"""

import math
import os
import sys
import time

import bpy
from mathutils import Matrix, Vector

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
import scene_reader  # noqa: E402  (tests/bench/scene_reader.py, found through the path above)


def to_blender(p):
    """An rtspheres point or vector (y up) in Blender's coordinates (z up)."""
    return Vector((p[0], -p[2], p[1]))


def metal_roughness(fuzz):
    """Cycles' Glossy roughness for an rtspheres metal of this fuzz. The lobes differ:
    rtspheres reflects about the mirror direction plus fuzz times a point of the unit
    ball (a lobe with a hard edge), GGX has a long tail. This matches their widths for
    small fuzz: the reflected direction of rtspheres spreads by fuzz / sqrt(5) per axis
    (RMS of one coordinate of the unit ball), a GGX of parameter alpha by about
    sqrt(2) alpha; Blender's roughness is sqrt(alpha)."""
    alpha = fuzz / math.sqrt(10.0)
    return math.sqrt(alpha)


def arguments():
    """The options after `--` as a dict; exits with a usage message on a bad one."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    usage = ("usage: blender -b ... -P render.py -- SCENE -o OUT.exr [--size WxH] [--spp N] "
             "[--max-depth N] [--seed N] [--threads N]")
    options = {"scene": None, "output": None, "size": None, "spp": None, "depth": None, "seed": None,
               "threads": 2}
    names = {"-o": "output", "--size": "size", "--spp": "spp", "--max-depth": "depth", "--seed": "seed",
             "--threads": "threads"}
    i = 0
    while i < len(argv):
        if argv[i] in names and i + 1 < len(argv):
            value = argv[i + 1]
            key = names[argv[i]]
            if key == "size":
                width, _, height = value.partition("x")
                options[key] = (int(width), int(height))
            elif key != "output":
                options[key] = int(value)
            else:
                options[key] = value
            i += 2
        elif options["scene"] is None and not argv[i].startswith("-"):
            options["scene"] = argv[i]
            i += 1
        else:
            sys.exit(usage)
    if options["scene"] is None or options["output"] is None:
        sys.exit(usage)
    return options


def settings(scene, render, threads):
    """Sets the render settings: Cycles on the CPU as the module's comment says."""
    scene.render.engine = "CYCLES"
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = render["spp"]
    cycles.seed = render["seed"]
    cycles.use_animated_seed = False
    cycles.use_adaptive_sampling = False
    cycles.use_denoising = False
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.blur_glossy = 0.0
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 1.0
    bounces = max(render["depth"] - 1, 0)
    for name in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
                 "volume_bounces", "transparent_max_bounces"):
        setattr(cycles, name, bounces)
    scene.render.threads_mode = "FIXED"
    scene.render.threads = threads
    scene.render.resolution_x = render["width"]
    scene.render.resolution_y = render["height"]
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    image = scene.render.image_settings
    image.file_format = "OPEN_EXR"
    image.color_depth = "32"
    image.color_mode = "RGBA"
    image.exr_codec = "ZIP"


def world(scene, sky):
    """The world shader: rtspheres' sky, not importance-sampled."""
    blender_world = bpy.data.worlds.new("sky")
    scene.world = blender_world
    blender_world.use_nodes = True
    blender_world.cycles.sampling_method = "NONE"
    nodes, links = blender_world.node_tree.nodes, blender_world.node_tree.links
    background = nodes["Background"]
    background.inputs["Strength"].default_value = 1.0
    if sky[0] == "constant":
        background.inputs["Color"].default_value = (*sky[1], 1.0)
        return
    # mix(bottom, top, 0.5 * (y + 1)) with y the direction's up component (Blender's z):
    # the world's Generated coordinates are the view direction.
    coordinates = nodes.new("ShaderNodeTexCoord")
    separate = nodes.new("ShaderNodeSeparateXYZ")
    blend = nodes.new("ShaderNodeMath")
    blend.operation = "MULTIPLY_ADD"
    blend.inputs[1].default_value = 0.5
    blend.inputs[2].default_value = 0.5
    mix = nodes.new("ShaderNodeMixRGB")
    mix.blend_type = "MIX"
    mix.use_clamp = False
    mix.inputs["Color1"].default_value = (*sky[1], 1.0)
    mix.inputs["Color2"].default_value = (*sky[2], 1.0)
    links.new(coordinates.outputs["Generated"], separate.inputs["Vector"])
    links.new(separate.outputs["Z"], blend.inputs[0])
    links.new(blend.outputs["Value"], mix.inputs["Fac"])
    links.new(mix.outputs["Color"], background.inputs["Color"])


def material_of(name, kind, albedo=None, fuzz=0.0, ior=1.5, emission=None, from_attributes=False):
    """A Cycles material for an rtspheres material type. With FROM_ATTRIBUTES its colour,
    roughness and IOR come from the point attributes bench_albedo, bench_roughness and
    bench_ior (the point clouds), else from the values given (the meshes)."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    output.target = "CYCLES"

    def attribute(attribute_name, socket_name):
        node = nodes.new("ShaderNodeAttribute")
        node.attribute_type = "GEOMETRY"
        node.attribute_name = attribute_name
        return node.outputs[socket_name]

    if kind == "lambertian":
        shader = nodes.new("ShaderNodeBsdfDiffuse")
        shader.inputs["Roughness"].default_value = 0.0
    elif kind == "metal":
        shader = nodes.new("ShaderNodeBsdfGlossy")
        shader.distribution = "GGX"
    elif kind == "dielectric":
        shader = nodes.new("ShaderNodeBsdfGlass")
        shader.distribution = "SHARP"
        shader.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    elif kind == "emissive":
        shader = nodes.new("ShaderNodeEmission")
        shader.inputs["Color"].default_value = (*emission, 1.0)
        shader.inputs["Strength"].default_value = 1.0
    else:
        raise scene_reader.SceneError("material type %r" % kind)
    if kind in ("lambertian", "metal"):
        if from_attributes:
            links.new(attribute("bench_albedo", "Vector"), shader.inputs["Color"])
        else:
            shader.inputs["Color"].default_value = (*albedo, 1.0)
    if kind == "metal":
        if from_attributes:
            links.new(attribute("bench_roughness", "Fac"), shader.inputs["Roughness"])
        else:
            shader.inputs["Roughness"].default_value = metal_roughness(fuzz)
    if kind == "dielectric":
        if from_attributes:
            links.new(attribute("bench_ior", "Fac"), shader.inputs["IOR"])
        else:
            shader.inputs["IOR"].default_value = ior
    links.new(shader.outputs[0], output.inputs["Surface"])
    return material


def point_cloud(name, spheres, material):
    """An object of analytic spheres: a mesh of their centres with radius, albedo, metal
    roughness (metal_roughness of the fuzz) and IOR per vertex, turned into points by a
    geometry-nodes modifier (Mesh to Points, radius from the attribute) that also sets
    MATERIAL."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([to_blender(centre) for centre, _, _ in spheres], [], [])
    values = {"bench_radius": ("FLOAT", [radius for _, radius, _ in spheres]),
              "bench_albedo": ("FLOAT_VECTOR", [m.get("albedo", (1.0, 1.0, 1.0)) for _, _, m in spheres]),
              "bench_roughness": ("FLOAT", [metal_roughness(m.get("fuzz", 0.0)) for _, _, m in spheres]),
              "bench_ior": ("FLOAT", [m.get("ior", 1.5) for _, _, m in spheres])}
    for attribute_name, (data_type, data) in values.items():
        attribute = mesh.attributes.new(attribute_name, data_type, "POINT")
        flat = [c for v in data for c in v] if data_type == "FLOAT_VECTOR" else data
        attribute.data.foreach_set("vector" if data_type == "FLOAT_VECTOR" else "value", flat)
    blender_object = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(blender_object)

    tree = bpy.data.node_groups.new(name, "GeometryNodeTree")
    tree.inputs.new("NodeSocketGeometry", "Geometry")
    tree.outputs.new("NodeSocketGeometry", "Geometry")
    group_input = tree.nodes.new("NodeGroupInput")
    group_output = tree.nodes.new("NodeGroupOutput")
    to_points = tree.nodes.new("GeometryNodeMeshToPoints")
    to_points.mode = "VERTICES"
    radius = tree.nodes.new("GeometryNodeInputNamedAttribute")
    radius.data_type = "FLOAT"
    radius.inputs["Name"].default_value = "bench_radius"
    set_material = tree.nodes.new("GeometryNodeSetMaterial")
    set_material.inputs["Material"].default_value = material
    tree.links.new(group_input.outputs[0], to_points.inputs["Mesh"])
    tree.links.new([o for o in radius.outputs if o.enabled][0], to_points.inputs["Radius"])
    tree.links.new(to_points.outputs["Points"], set_material.inputs["Geometry"])
    tree.links.new(set_material.outputs["Geometry"], group_output.inputs[0])
    modifier = blender_object.modifiers.new(name, "NODES")
    modifier.node_group = tree


def sphere_light(name, centre, radius, emission):
    """A point light of RADIUS for an emissive sphere of that radius and radiance EMISSION.
    Cycles (3.4) makes a point light of power P and radius r a disc of radius r facing
    the shading point, of radiance P / (4 pi^2 r^2): a sphere of that radiance has power
    4 pi^2 r^2 L, so that is the power given. The disc subtends a little less than the
    sphere (by a factor d^2 / (d^2 + r^2) in irradiance at distance d from the centre)."""
    strength = max(emission)
    light = bpy.data.lights.new(name, "POINT")
    light.shadow_soft_size = radius
    light.color = tuple(c / strength for c in emission) if strength > 0 else (1.0, 1.0, 1.0)
    light.energy = 4.0 * math.pi * math.pi * radius * radius * strength
    blender_object = bpy.data.objects.new(name, light)
    blender_object.location = to_blender(centre)
    bpy.context.scene.collection.objects.link(blender_object)


def quads_mesh(name, quads, materials):
    """One mesh object of every quad, a material slot per rtspheres material it uses."""
    slots = sorted({material for _, _, _, material in quads})
    vertices, faces, face_slots = [], [], []
    for corner, u, v, material in quads:
        first = len(vertices)
        q = [corner, tuple(corner[k] + u[k] for k in range(3)),
             tuple(corner[k] + u[k] + v[k] for k in range(3)), tuple(corner[k] + v[k] for k in range(3))]
        vertices.extend(to_blender(p) for p in q)
        faces.append((first, first + 1, first + 2, first + 3))
        face_slots.append(slots.index(material))
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    for slot in slots:
        mesh.materials.append(materials[slot])
    mesh.polygons.foreach_set("material_index", face_slots)
    mesh.update()
    blender_object = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(blender_object)


def camera(scene, read):
    """The camera: at `from`, looking at `at`, `up` up, vertical fov, thin lens."""
    settings_read = read.camera
    eye = Vector(settings_read["from"])
    w = (eye - Vector(settings_read["at"])).normalized()           # the camera's back (+z)
    u = Vector(settings_read["up"]).cross(w).normalized()           # its right (+x)
    v = w.cross(u)                                                  # its up (+y)
    basis = [to_blender(u), to_blender(v), to_blender(w)]
    transform = Matrix.Identity(4)
    for row in range(3):
        for column in range(3):
            transform[row][column] = basis[column][row]
        transform[row][3] = to_blender(eye)[row]
    data = bpy.data.cameras.new("camera")
    data.type = "PERSP"
    data.sensor_fit = "VERTICAL"
    data.angle_y = math.radians(settings_read["fov"])
    data.clip_start = 1e-4
    data.clip_end = 1e6
    if settings_read["aperture"] > 0:
        data.dof.use_dof = True
        data.dof.focus_distance = read.focus_distance()
        # Cycles' lens radius is the focal length (m) / (2 f-stop); the diameter is the
        # scene's aperture.
        data.dof.aperture_fstop = data.lens * 1e-3 / settings_read["aperture"]
        data.dof.aperture_blades = 0
        data.dof.aperture_ratio = 1.0
    blender_object = bpy.data.objects.new("camera", data)
    blender_object.matrix_world = transform
    scene.collection.objects.link(blender_object)
    scene.camera = blender_object


def build(read):
    """Builds the scene READ (a scene_reader.Scene) into Blender's current scene."""
    scene = bpy.context.scene
    world(scene, read.sky)
    camera(scene, read)
    by_type = {}
    for centre, radius, name in read.spheres:
        material = read.materials[name]
        if material["type"] == "emissive":
            sphere_light("light_%d" % len(by_type.get("emissive", [])), centre, radius, material["emission"])
            by_type.setdefault("emissive", []).append(name)
        else:
            by_type.setdefault(material["type"], []).append((centre, radius, material))
    for kind in ("lambertian", "metal", "dielectric"):
        if kind in by_type:
            point_cloud("spheres_" + kind, by_type[kind], material_of(kind + "_points", kind, from_attributes=True))
    if read.quads:
        materials = {}
        for name in {material for _, _, _, material in read.quads}:
            m = read.materials[name]
            materials[name] = material_of(name, m["type"], albedo=m.get("albedo"), fuzz=m.get("fuzz", 0.0),
                                          ior=m.get("ior", 1.5), emission=m.get("emission"))
        quads_mesh("quads", read.quads, materials)


def main():
    options = arguments()
    started = time.perf_counter()
    try:
        read = scene_reader.read_scene(options["scene"])
    except (scene_reader.SceneError, OSError) as failure:
        sys.exit("cycles: %s" % failure)
    render = read.render
    if options["size"]:
        render["width"], render["height"] = options["size"]
    for key in ("spp", "depth", "seed"):
        if options[key] is not None:
            render[key] = options[key]
    # The factory start-up scene's cube, light and camera go.
    for blender_object in list(bpy.data.objects):
        bpy.data.objects.remove(blender_object)
    scene = bpy.context.scene
    settings(scene, render, options["threads"])
    build(read)
    built = time.perf_counter() - started
    before = time.perf_counter()
    bpy.ops.render.render(write_still=False)
    seconds = time.perf_counter() - before
    bpy.data.images["Render Result"].save_render(filepath=os.path.abspath(options["output"]), scene=scene)
    print("cycles: %s %dx%d %d spp in %.3f s (render call), scene built in %.3f s, Blender %s"
          % (options["scene"], render["width"], render["height"], render["spp"], seconds, built,
             bpy.app.version_string))
    sys.stdout.flush()


main()
