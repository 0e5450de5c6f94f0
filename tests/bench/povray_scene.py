"""povray_scene.py: writes an rtspheres scene of spheres (scenes/three-balls.txt) as a
POV-Ray 3.7 scene, for `make bench`'s povray-three-balls row (tests/bench/peers.sh): the
Whitted frame of rtspheres (--integrator whitted) beside what POV-Ray, a classic
Whitted ray tracer, takes for the same frame.

    python3 tests/bench/povray_scene.py SCENE OUT.pov

The scene is read by tests/bench/scene_reader.py (not rtspheres' parser). What is the
same: the spheres, the camera (vertical field of view, aspect), the gradient sky, the
materials' colours, the ambient term (rtspheres' default 0.03), Phong highlights of
exponent 32 (specular 0.04 on lambertian, the albedo on metal: rtspheres' defaults),
trace depth = the scene's depth (see the povray command line in peers.sh). What cannot
be: POV-Ray is not physically based. Its light has no 1/pi in the diffuse term and
fades as 2 / (1 + (d / D)^2), so the emissive sphere becomes a light of colour L (the
radiance) with D = r / sqrt(2): at distance d >> r that gives L r^2 / d^2, what a
Lambertian surface facing a sphere light of radiance L and radius r reflects over its
albedo. It is an 8x8 area light on a disc of the sphere's radius facing each point
(circular, orient, adaptive 1, jitter), and the sphere itself stays visible in
reflections (looks_like). Glass traces both reflection (Fresnel) and refraction at
every hit, where rtspheres' Whitted picks one per sample.

Coordinates: POV-Ray is left-handed, so z is negated ((x, y, z) -> (x, y, -z)), which
keeps the image the same way round.
"""

import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scene_reader  # noqa: E402  (tests/bench/scene_reader.py)

AMBIENT = 0.03          # rtspheres' default `ambient` (docs/scene-format.md)
PHONG_SIZE = 32         # rtspheres' default `phong` exponent
LAMBERTIAN_SPECULAR = 0.04


def vector(v):
    """A POV-Ray vector from an rtspheres point or direction (z negated)."""
    return "<%.9g, %.9g, %.9g>" % (v[0], v[1], -v[2])


def colour(c):
    return "rgb <%.9g, %.9g, %.9g>" % tuple(c)


def material_text(material):
    """The texture (and interior) of an rtspheres material, non-emissive."""
    kind = material["type"]
    if kind == "lambertian":
        return ("texture { pigment { %s } finish { ambient %g diffuse 1 phong %g phong_size %d } }"
                % (colour(material["albedo"]), AMBIENT, LAMBERTIAN_SPECULAR, PHONG_SIZE))
    if kind == "metal":
        return ("texture { pigment { %s } finish { ambient %g diffuse 0 reflection { %s } "
                "phong 1 phong_size %d metallic } }"
                % (colour(material["albedo"]), AMBIENT, colour(material["albedo"]), PHONG_SIZE))
    if kind == "dielectric":
        return ("texture { pigment { rgbf <1, 1, 1, 1> } finish { ambient 0 diffuse 0 "
                "reflection { 0, 1 fresnel on } conserve_energy } } interior { ior %g }" % material["ior"])
    raise scene_reader.SceneError("povray_scene: material type %r" % kind)


def write(read, handle):
    """Writes the scene READ (a scene_reader.Scene) to HANDLE as POV-Ray 3.7 text."""
    render, camera = read.render, read.camera
    aspect = render["width"] / render["height"]
    horizontal_fov = 2 * math.degrees(math.atan(aspect * math.tan(math.radians(camera["fov"]) / 2)))
    if camera["aperture"] > 0:
        raise scene_reader.SceneError("povray_scene: a thin-lens camera is not written (aperture 0 only)")
    if read.quads:
        raise scene_reader.SceneError("povray_scene: spheres only (no quads or boxes)")
    out = handle.write
    out("// Written by tests/bench/povray_scene.py from an rtspheres scene; not for editing.\n")
    out("#version 3.7;\n")
    out("global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level %d }\n" % render["depth"])
    out("camera { perspective location %s look_at %s sky %s right x * %.9g up y angle %.9g }\n"
        % (vector(camera["from"]), vector(camera["at"]), vector(camera["up"]), aspect, horizontal_fov))
    if read.sky[0] == "gradient":
        # gradient y is y itself on 0..1; scaled by 2 and moved down it spans -1..1
        out("sky_sphere { pigment { gradient y color_map { [0 %s] [1 %s] } scale 2 translate -y } }\n"
            % (colour(read.sky[1]), colour(read.sky[2])))
    else:
        out("background { %s }\n" % colour(read.sky[1]))
    for centre, radius, name in read.spheres:
        material = read.materials[name]
        if material["type"] == "emissive":
            out("light_source { %s %s fade_distance %.9g fade_power 2\n"
                % (vector(centre), colour(material["emission"]), radius / math.sqrt(2)))
            out("    area_light <%.9g, 0, 0>, <0, %.9g, 0>, 8, 8 adaptive 1 jitter circular orient\n"
                % (2 * radius, 2 * radius))
            out("    looks_like { sphere { 0, %.9g texture { pigment { %s } finish { emission 1 diffuse 0 } } } }\n"
                "}\n" % (radius, colour(material["emission"])))
        else:
            out("sphere { %s, %.9g %s }\n" % (vector(centre), radius, material_text(material)))


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: python3 tests/bench/povray_scene.py SCENE OUT.pov")
    try:
        read = scene_reader.read_scene(sys.argv[1])
        with open(sys.argv[2], "w", encoding="utf-8") as handle:
            write(read, handle)
    except (scene_reader.SceneError, OSError) as failure:
        sys.exit("povray_scene: %s" % failure)


main()
