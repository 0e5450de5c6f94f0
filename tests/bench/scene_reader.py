"""scene_reader.py: reads the rtspheres scene files that `make bench` gives its peers
(scenes/weekend.txt, scenes/cornell.txt, scenes/three-balls.txt) for the scripts that
rebuild them in other renderers (tests/bench/cycles/render.py for Blender Cycles,
tests/bench/povray_scene.py for POV-Ray).

A yardstick shares no code with what it measures (as tests/bench/reference_weekend.c):
this is a reader of just the statements those three files use, written from
docs/scene-format.md, not the project's parser. Anything else is an error naming the
line. What it reads:

    set NAME EXPRESSION
    render [size W H] [spp N] [depth N] [seed N]
    camera [from X Y Z] [at X Y Z] [up X Y Z] [fov DEGREES] [aperture A] [focus D]
    sky gradient R G B  R G B          sky constant R G B
    material NAME lambertian R G B | metal R G B [fuzz F] | dielectric IOR
                  | emissive R G B [strength S]
    sphere X Y Z RADIUS MATERIAL       quad QX QY QZ UX UY UZ VX VY VZ MATERIAL
    box X0 Y0 Z0 X1 Y1 Z1 [MATERIAL]   (inside groups)
    group [NAME] [material MATERIAL] {  with rotate AX AY AZ DEG / translate X Y Z first
    }

Numbers are literals, $variables or parenthesised expressions with + - * / ^, unary
minus, sin cos tan sqrt abs min max and pi (docs/scene-format.md, "Numbers and
expressions"). Transforms are applied here: every shape comes out in world coordinates
(y up, as rtspheres has it), a box as its six quads.

usage (a check from the shell):  python3 tests/bench/scene_reader.py SCENE
"""

import math
import sys

# The defaults of docs/scene-format.md for the clauses these scenes may leave out.
RENDER_DEFAULTS = {"width": 640, "height": 360, "spp": 64, "depth": 16, "seed": 1}
CAMERA_DEFAULTS = {"from": (0.0, 0.0, 1.0), "at": (0.0, 0.0, 0.0), "up": (0.0, 1.0, 0.0),
                   "fov": 40.0, "aperture": 0.0, "focus": 0.0}


class SceneError(Exception):
    """A statement this reader does not take, or a bad value; the message names the line."""


# ---- expressions -----------------------------------------------------------------------

FUNCTIONS = {"sin": (1, math.sin), "cos": (1, math.cos), "tan": (1, math.tan),
             "sqrt": (1, math.sqrt), "abs": (1, abs), "min": (2, min), "max": (2, max)}


def expression_tokens(text):
    """Splits an expression into numbers, names, $variables and one-character operators."""
    tokens, i = [], 0
    while i < len(text):
        c = text[i]
        if c.isspace():
            i += 1
        elif c.isdigit() or c == ".":
            j = i
            while j < len(text) and (text[j].isdigit() or text[j] == "."):
                j += 1
            if j < len(text) and text[j] in "eE":
                k = j + 1
                if k < len(text) and text[k] in "+-":
                    k += 1
                if k < len(text) and text[k].isdigit():
                    j = k
                    while j < len(text) and text[j].isdigit():
                        j += 1
            tokens.append(("number", float(text[i:j])))
            i = j
        elif c.isalpha() or c == "_" or c == "$":
            j = i + 1
            while j < len(text) and (text[j].isalnum() or text[j] == "_"):
                j += 1
            tokens.append(("variable" if c == "$" else "name", text[i + 1:j] if c == "$" else text[i:j]))
            i = j
        elif c in "+-*/^(),":
            tokens.append((c, None))
            i += 1
        else:
            raise SceneError("unexpected character %r in expression %r" % (c, text))
    return tokens


def evaluate(text, variables):
    """Returns the value of expression TEXT with the given variables (a dict)."""
    tokens = expression_tokens(text)
    position = [0]

    def peek():
        return tokens[position[0]][0] if position[0] < len(tokens) else None

    def take(kind):
        if peek() != kind:
            raise SceneError("expected %r in expression %r" % (kind, text))
        position[0] += 1
        return tokens[position[0] - 1][1]

    def sum_():
        value = product()
        while peek() in ("+", "-"):
            operator = tokens[position[0]][0]
            position[0] += 1
            right = product()
            value = value + right if operator == "+" else value - right
        return value

    def product():
        value = unary()
        while peek() in ("*", "/"):
            operator = tokens[position[0]][0]
            position[0] += 1
            right = unary()
            if operator == "/" and right == 0:
                raise SceneError("division by zero in %r" % text)
            value = value * right if operator == "*" else value / right
        return value

    def unary():
        if peek() in ("+", "-"):
            operator = tokens[position[0]][0]
            position[0] += 1
            value = unary()
            return -value if operator == "-" else value
        return power()

    def power():
        base = primary()
        if peek() == "^":
            position[0] += 1
            return base ** unary()      # right to left, and 2^-1 is 0.5
        return base

    def primary():
        kind = peek()
        if kind == "number":
            return take("number")
        if kind == "variable":
            name = take("variable")
            if name not in variables:
                raise SceneError("undefined variable $%s" % name)
            return variables[name]
        if kind == "(":
            take("(")
            value = sum_()
            take(")")
            return value
        if kind == "name":
            name = take("name")
            if name == "pi":
                return math.pi
            if name not in FUNCTIONS:
                raise SceneError("unknown name %r in %r" % (name, text))
            count, function = FUNCTIONS[name]
            take("(")
            arguments = [sum_()]
            while peek() == ",":
                take(",")
                arguments.append(sum_())
            take(")")
            if len(arguments) != count:
                raise SceneError("%s takes %d argument(s)" % (name, count))
            return float(function(*arguments))
        raise SceneError("bad expression %r" % text)

    value = sum_()
    if position[0] != len(tokens):
        raise SceneError("unexpected %r in expression %r" % (tokens[position[0]][0], text))
    if not math.isfinite(value):
        raise SceneError("expression %r is not a finite number" % text)
    return value


# ---- statements ------------------------------------------------------------------------

def line_words(line):
    """Splits a statement line into words; a parenthesised expression is one word."""
    words, depth, current = [], 0, ""
    for c in line:
        if c.isspace() and depth == 0:
            if current:
                words.append(current)
            current = ""
            continue
        depth += (c == "(") - (c == ")")
        current += c
    if current:
        words.append(current)
    if depth != 0:
        raise SceneError("unbalanced parentheses")
    return words


def rotate(point, axis, degrees):
    """Turns POINT about AXIS through the origin by DEGREES, right-handed (Rodrigues)."""
    length = math.sqrt(sum(a * a for a in axis))
    if length == 0:
        raise SceneError("rotate: zero axis")
    k = [a / length for a in axis]
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    dot = sum(k[i] * point[i] for i in range(3))
    cross = (k[1] * point[2] - k[2] * point[1], k[2] * point[0] - k[0] * point[2],
             k[0] * point[1] - k[1] * point[0])
    return tuple(point[i] * c + cross[i] * s + k[i] * dot * (1 - c) for i in range(3))


def box_quads(low, high):
    """The six outward-facing quads (corner, u, v) of the axis-aligned box LOW..HIGH."""
    (x0, y0, z0), (x1, y1, z1) = low, high
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    return [((x1, y0, z1), (0, 0, -dz), (0, dy, 0)),    # +X
            ((x0, y0, z0), (0, 0, dz), (0, dy, 0)),     # -X
            ((x0, y1, z1), (dx, 0, 0), (0, 0, -dz)),    # +Y
            ((x0, y0, z0), (dx, 0, 0), (0, 0, dz)),     # -Y
            ((x0, y0, z1), (dx, 0, 0), (0, dy, 0)),     # +Z
            ((x1, y0, z0), (-dx, 0, 0), (0, dy, 0))]    # -Z


class Scene:
    """What the three bench scenes hold, in world coordinates (y up).

    render:    dict width, height, spp, depth (path segments), seed
    camera:    dict from, at, up (3-tuples), fov (vertical, degrees), aperture (lens
               diameter), focus (0: the distance from `from` to `at`)
    sky:       ("gradient", bottom, top) or ("constant", colour)
    materials: name -> dict type (lambertian, metal, dielectric, emissive) and albedo,
               fuzz, ior, emission (colour x strength) as the type has them
    spheres:   list of (centre, radius, material name)
    quads:     list of (corner, u, v, material name); boxes come as six quads each
    """

    def __init__(self):
        self.render = dict(RENDER_DEFAULTS)
        self.camera = dict(CAMERA_DEFAULTS)
        self.sky = ("gradient", (1.0, 1.0, 1.0), (0.5, 0.7, 1.0))
        self.materials = {}
        self.spheres = []
        self.quads = []

    def focus_distance(self):
        """The camera's focus distance, the distance to `at` when the scene says 0."""
        if self.camera["focus"] > 0:
            return self.camera["focus"]
        return math.dist(self.camera["from"], self.camera["at"])

    def material_used(self, name):
        """The material NAME (a dict as in `materials`); an unknown name is an error."""
        if name not in self.materials:
            raise SceneError("unknown material %r" % name)
        return self.materials[name]


def read_scene(path, defines=None):
    """Reads the scene file PATH (with -D style DEFINES, a dict of name -> number that
    wins over the file's `set`) and returns a Scene; raises SceneError naming the line."""
    scene = Scene()
    variables = dict(defines or {})
    groups = []     # open blocks: dict material, transforms, contents_started
    with open(path, encoding="utf-8") as handle:
        lines = handle.read().splitlines()
    for number, raw in enumerate(lines, 1):
        try:
            read_statement(scene, raw.split("#", 1)[0].strip(), variables, groups, defines or {})
        except SceneError as error:
            raise SceneError("%s:%d: %s" % (path, number, error)) from None
    if groups:
        raise SceneError("%s: a group is not closed" % path)
    return scene


def read_statement(scene, line, variables, groups, defines):
    """Adds the statement LINE (comment stripped) to SCENE."""
    if not line:
        return
    if line.startswith("set "):
        name, _, text = line[4:].strip().partition(" ")
        if name not in defines:
            variables[name] = evaluate(text, variables)
        return
    words = line_words(line)
    keyword, arguments = words[0], words[1:]

    def numbers(count, start=0):
        values = arguments[start:start + count]
        if len(values) != count:
            raise SceneError("%s: expected %d numbers" % (keyword, count))
        return [evaluate(v, variables) for v in values]

    def clauses(table):
        """Reads `name values...` clauses; TABLE maps a clause name to its count."""
        found, i = {}, 0
        while i < len(arguments):
            name = arguments[i]
            if name not in table or name in found:
                raise SceneError("%s: unexpected %r" % (keyword, name))
            count = table[name]
            found[name] = numbers(count, i + 1)
            i += 1 + count
        return found

    def place(point):
        for block in reversed(groups):     # inner blocks' transforms first
            for kind, values in block["transforms"]:
                if kind == "rotate":
                    point = rotate(point, values[:3], values[3])
                else:
                    point = tuple(point[k] + values[k] for k in range(3))
        return point

    def place_vector(vector):
        origin = place((0.0, 0.0, 0.0))
        moved = place(tuple(vector))
        return tuple(moved[k] - origin[k] for k in range(3))

    def shape_material(index):
        if len(arguments) > index:
            if len(arguments) != index + 1:
                raise SceneError("%s: too many arguments" % keyword)
            name = arguments[index]
        else:
            name = next((b["material"] for b in reversed(groups) if b["material"]), None)
            if name is None:
                raise SceneError("%s: no material" % keyword)
        scene.material_used(name)
        return name

    if keyword in ("rotate", "translate"):
        if not groups or groups[-1]["contents_started"]:
            raise SceneError("transforms come first in a group")
        groups[-1]["transforms"].append((keyword, numbers(4 if keyword == "rotate" else 3)))
        if len(arguments) != (4 if keyword == "rotate" else 3):
            raise SceneError("%s: wrong number of arguments" % keyword)
        return
    if groups:
        groups[-1]["contents_started"] = True
    if keyword == "render":
        found = clauses({"size": 2, "spp": 1, "depth": 1, "seed": 1})
        for name, values in found.items():
            if any(v != int(v) for v in values):
                raise SceneError("render %s: whole numbers only" % name)
            if name == "size":
                scene.render["width"], scene.render["height"] = int(values[0]), int(values[1])
            else:
                scene.render[name] = int(values[0])
    elif keyword == "camera":
        found = clauses({"from": 3, "at": 3, "up": 3, "fov": 1, "aperture": 1, "focus": 1})
        for name, values in found.items():
            scene.camera[name] = tuple(values) if len(values) == 3 else values[0]
    elif keyword == "sky":
        kind = arguments[0] if arguments else ""
        if kind == "gradient" and len(arguments) == 7:
            values = numbers(6, 1)
            scene.sky = ("gradient", tuple(values[:3]), tuple(values[3:]))
        elif kind == "constant" and len(arguments) == 4:
            scene.sky = ("constant", tuple(numbers(3, 1)))
        else:
            raise SceneError("sky: only `gradient R G B R G B` and `constant R G B`")
    elif keyword == "material":
        read_material(scene, arguments, variables)
    elif keyword == "sphere":
        x, y, z, radius = numbers(4)
        if radius <= 0:
            raise SceneError("sphere: radius must be > 0")
        scene.spheres.append((place((x, y, z)), radius, shape_material(4)))
    elif keyword == "quad":
        q = numbers(9)
        scene.quads.append((place(tuple(q[0:3])), place_vector(q[3:6]), place_vector(q[6:9]),
                            shape_material(9)))
    elif keyword == "box":
        b = numbers(6)
        material = shape_material(6)
        for corner, u, v in box_quads(b[0:3], b[3:6]):
            scene.quads.append((place(corner), place_vector(u), place_vector(v), material))
    elif keyword == "group":
        if arguments[-1:] != ["{"]:
            raise SceneError("group: `{` ends the line")
        rest, material = arguments[:-1], None
        if rest and rest[0] != "material":
            rest = rest[1:]         # the group's name: nothing here refers to it
        if rest:
            if len(rest) != 2 or rest[0] != "material":
                raise SceneError("group: only [NAME] [material MATERIAL]")
            material = rest[1]
            scene.material_used(material)
        groups.append({"material": material, "transforms": [], "contents_started": False})
    elif keyword == "}":
        if not groups or arguments:
            raise SceneError("unexpected `}`")
        groups.pop()
    else:
        raise SceneError("statement %r is not one the bench's scene reader takes" % keyword)


def read_material(scene, arguments, variables):
    """Adds `material NAME TYPE ...` (ARGUMENTS after the keyword) to SCENE."""
    if len(arguments) < 2:
        raise SceneError("material: NAME TYPE ...")
    name, kind, rest = arguments[0], arguments[1], arguments[2:]
    values = [evaluate(v, variables) if v not in ("fuzz", "strength") else v for v in rest]
    if kind == "lambertian" and len(values) == 3:
        material = {"type": kind, "albedo": tuple(values)}
    elif kind == "metal" and len(values) in (3, 5) and (len(values) == 3 or values[3] == "fuzz"):
        material = {"type": kind, "albedo": tuple(values[:3]),
                    "fuzz": values[4] if len(values) == 5 else 0.0}
    elif kind == "dielectric" and len(values) == 1:
        material = {"type": kind, "ior": values[0]}
    elif kind == "emissive" and len(values) in (3, 5) and (len(values) == 3 or values[3] == "strength"):
        strength = values[4] if len(values) == 5 else 1.0
        material = {"type": kind, "emission": tuple(c * strength for c in values[:3])}
    else:
        raise SceneError("material %s: %r with these arguments is not one the bench's reader takes"
                         % (name, kind))
    scene.materials[name] = material


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python3 tests/bench/scene_reader.py SCENE")
    try:
        read = read_scene(sys.argv[1])
    except (SceneError, OSError) as failure:
        sys.exit("scene_reader: %s" % failure)
    print("render", read.render)
    print("camera", read.camera, "focus distance %.4g" % read.focus_distance())
    print("sky", read.sky)
    print("%d materials, %d spheres, %d quads" % (len(read.materials), len(read.spheres), len(read.quads)))
