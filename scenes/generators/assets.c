/* assets.c: writes the images and meshes that the example scenes of scenes/ use.
 *
 * Build and run from the repository root:
 *   cc -std=c11 -O2 scenes/generators/assets.c -lm -o /tmp/assets && /tmp/assets scenes/assets
 * and, for the large test and benchmark meshes (written at run time, never committed):
 *   /tmp/assets DIR N          writes only DIR/icosphere-N.obj (N = 0 .. 9)
 *
 * Self-contained: C11, libc and libm only. Everything is procedural and deterministic:
 * the noise is a hash of integer lattice coordinates and a fixed seed, so every run on
 * every platform writes the same bytes (up to the C library's printf of doubles, which
 * is exact for the %.6f used here).
 *
 * `assets DIR` writes (DIR and DIR/skybox are created when missing):
 *   skybox/px.ppm nx.ppm py.ppm ny.ppm pz.ppm nz.ppm
 *       256x256 each, the faces of one procedural sky as an OpenGL cube map: a blue
 *       gradient sky with light clouds, a sun with a glow (direction SUN below), a hazy
 *       horizon and a darker ground. Each pixel's direction follows the OpenGL cube-map
 *       convention, with s, t in [-1, 1] at the pixel centre (s to the right, t down):
 *         +X (1, -t, -s)   -X (-1, -t, s)   +Y (s, 1, t)   -Y (s, -1, -t)
 *         +Z (s, -t, 1)    -Z (-s, -t, -1)
 *       and the colour is a function of that direction only, so the faces meet without
 *       seams. Use: sky box "px.ppm" "nx.ppm" "py.ppm" "ny.ppm" "pz.ppm" "nz.ppm".
 *   earth.ppm
 *       512x256 equirectangular "planet": continents from 3D value noise (evaluated on
 *       the unit sphere, so there is no seam and no pinching at the poles), oceans,
 *       deserts, mountains and polar caps. Column u, row v (from the top) is the point
 *       at longitude phi = 2 pi (u - 1/2) and height y = cos(pi v), i.e. the direction
 *       (cos(lat) cos(phi), y, -cos(lat) sin(phi)): the mapping rtspheres' spheres use
 *       (the one of "Ray Tracing: The Next Week"), so the north pole is the top row.
 *   bumps.ppm
 *       256x256 tangent-space normal map, a grid of 8x8 round bumps, each pixel the unit
 *       normal n encoded as n * 0.5 + 0.5 (flat is 128 128 255). Convention as OpenGL,
 *       Blender and glTF: +X towards the image's right, +Y towards the image's top,
 *       +Z out of the surface. These are raw vector values, not sRGB colours.
 *   crystal.obj
 *       a faceted crystal ball: an icosphere of subdivision 1 (80 triangles, 42
 *       positions), radius 1, centred at the origin; flat facets (no vn lines); vt
 *       coordinates per corner (spherical, OBJ convention: v = 1 at the top), with the
 *       u seam fixed per triangle.
 *   stand.obj
 *       a stand for the crystal ball: an octagonal pedestal (a flat bottom, a foot, a
 *       tapered stem, a collar flaring out to the rim and a shallow cup inside it: 40
 *       faces, quads and triangles), base at y = 0, rim corners at radius
 *       STAND_TOP_RADIUS and height STAND_HEIGHT; vn lines make each part smooth around
 *       the octagon and the edges between the parts hard. A sphere of radius 1 resting
 *       on the rim has its centre at y = STAND_HEIGHT + sqrt(1 - STAND_TOP_RADIUS^2) =
 *       1.3; crystal.obj (unrotated, its flat facets inside the unit sphere) sits on it
 *       with its centre at y = CRYSTAL_REST_Y = 1.33, clear of the rim by less than 0.015
 *       and of the cup everywhere.
 *
 * `assets DIR N` writes only DIR/icosphere-N.obj: an icosphere of subdivision N
 * (20 * 4^N triangles, 10 * 4^N + 2 positions; N = 7 gives 327,680 triangles and about
 * 30 MB, N = 8 1,310,720 triangles), radius 1, centred at the origin, with smooth vertex
 * normals (vn = the position) and spherical vt coordinates (seam fixed per triangle).
 *
 * Images are binary PPM (P6), 8 bits per channel. Colour images (the sky, earth.ppm)
 * hold sRGB-encoded values of the linear colours computed here.
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define PI 3.14159265358979323846

#define ASSETS_SEED 0x5eed0002u

#define SKY_SIZE 256
#define EARTH_WIDTH 512
#define EARTH_HEIGHT 256
#define BUMPS_SIZE 256
#define BUMPS_CELLS 8

#define STAND_SIDES 8
#define STAND_HEIGHT 0.5
#define STAND_TOP_RADIUS 0.6
#define STAND_CUP_BOTTOM 0.1
/* Where to put crystal.obj's centre (unrotated) on the stand, found numerically: at 1.316
 * the rim's corners touch its facets, but a few of its vertices near the rim dip 0.014
 * into the cup's octagonal facets; from 1.33 on it clears the whole stand. */
#define CRYSTAL_REST_Y 1.33

/* ------------------------------------------------------------------ small vector maths */

typedef struct vec3 {
    double x, y, z;
} vec3;

static vec3 v3(double x, double y, double z)
{
    vec3 v = {x, y, z};
    return v;
}

static vec3 add(vec3 a, vec3 b) { return v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static vec3 scale(vec3 a, double s) { return v3(a.x * s, a.y * s, a.z * s); }
static double dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static vec3 normalize(vec3 a) { return scale(a, 1.0 / sqrt(dot(a, a))); }
static vec3 mix3(vec3 a, vec3 b, double t) { return add(scale(a, 1.0 - t), scale(b, t)); }

static double clamp01(double x) { return x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x; }

static double smoothstep(double edge0, double edge1, double x)
{
    double t = clamp01((x - edge0) / (edge1 - edge0));
    return t * t * (3.0 - 2.0 * t);
}

/* ------------------------------------------------------------------ noise */

/* A 32-bit integer hash (Chris Wellons' "lowbias32"). */
static uint32_t hash32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

/* A value in [0, 1) for the lattice point (i, j, k) of noise channel `channel`. */
static double lattice(int i, int j, int k, uint32_t channel)
{
    uint32_t h = hash32(ASSETS_SEED ^ hash32(channel));
    h = hash32(h ^ (uint32_t)i);
    h = hash32(h ^ (uint32_t)j * 0x9e3779b9u);
    h = hash32(h ^ (uint32_t)k * 0x85ebca6bu);
    return (double)(h >> 8) * (1.0 / 16777216.0);
}

/* Trilinear value noise in [0, 1] with a quintic fade. */
static double value_noise(vec3 p, uint32_t channel)
{
    double fx = floor(p.x), fy = floor(p.y), fz = floor(p.z);
    int i = (int)fx, j = (int)fy, k = (int)fz;
    double tx = p.x - fx, ty = p.y - fy, tz = p.z - fz;
    tx = tx * tx * tx * (tx * (tx * 6.0 - 15.0) + 10.0);
    ty = ty * ty * ty * (ty * (ty * 6.0 - 15.0) + 10.0);
    tz = tz * tz * tz * (tz * (tz * 6.0 - 15.0) + 10.0);
    double result = 0.0;
    for (int corner = 0; corner < 8; corner++) {
        int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
        double w = (dx ? tx : 1.0 - tx) * (dy ? ty : 1.0 - ty) * (dz ? tz : 1.0 - tz);
        result += w * lattice(i + dx, j + dy, k + dz, channel);
    }
    return result;
}

/* Fractal sum of octaves of value noise, normalised to [0, 1]. */
static double fbm(vec3 p, int octaves, uint32_t channel)
{
    double sum = 0.0, weight = 0.5, total = 0.0;
    for (int o = 0; o < octaves; o++) {
        sum += weight * value_noise(p, channel + (uint32_t)o);
        total += weight;
        weight *= 0.5;
        /* An irrational-ish offset per octave keeps the lattices from lining up. */
        p = add(scale(p, 2.03), v3(17.13, 5.71, 11.37));
    }
    return sum / total;
}

/* ------------------------------------------------------------------ files */

static const char *output_directory;

static void make_directory(const char *path)
{
    if (mkdir(path, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "assets: cannot create directory '%s': %s\n", path, strerror(errno));
        exit(1);
    }
}

static FILE *open_output(const char *name, char *path, size_t path_size)
{
    snprintf(path, path_size, "%s/%s", output_directory, name);
    FILE *f = fopen(path, "wb");
    if (f == NULL) {
        fprintf(stderr, "assets: cannot write '%s': %s\n", path, strerror(errno));
        exit(1);
    }
    return f;
}

static void close_output(FILE *f, const char *path)
{
    if (ferror(f) || fclose(f) != 0) {
        fprintf(stderr, "assets: error writing '%s'\n", path);
        exit(1);
    }
    printf("wrote %s\n", path);
}

/* The sRGB encoding (IEC 61966-2-1) of a linear value, as an 8-bit code. */
static unsigned char srgb8(double linear)
{
    double c = clamp01(linear);
    c = c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
    return (unsigned char)floor(c * 255.0 + 0.5);
}

/* An 8-bit code for a value in [0, 1] stored as it is (normal maps). */
static unsigned char raw8(double value)
{
    return (unsigned char)floor(clamp01(value) * 255.0 + 0.5);
}

/* Writes an RGB image (3 bytes per pixel, rows top to bottom) as binary PPM. */
static void write_ppm(const char *name, int width, int height, const unsigned char *rgb)
{
    char path[4096];
    FILE *f = open_output(name, path, sizeof path);
    fprintf(f, "P6\n%d %d\n255\n", width, height);
    fwrite(rgb, 3, (size_t)width * (size_t)height, f);
    close_output(f, path);
}

/* ------------------------------------------------------------------ the sky box */

/* Linear radiance of the procedural sky in direction d (unit length). */
static vec3 sky_colour(vec3 d)
{
    const vec3 sun = normalize(v3(0.35, 0.26, -0.9));
    const vec3 zenith = v3(0.10, 0.25, 0.66);
    const vec3 horizon = v3(0.62, 0.72, 0.86);
    const vec3 haze = v3(0.55, 0.58, 0.60);
    const vec3 ground_near = v3(0.20, 0.19, 0.15);
    const vec3 ground_far = v3(0.075, 0.07, 0.055);

    vec3 colour;
    if (d.y >= 0.0) {
        /* Blue overhead, pale towards the horizon. */
        colour = mix3(zenith, horizon, pow(1.0 - d.y, 4.0));
        /* Clouds on a plane above the camera, fading out towards the horizon. */
        if (d.y > 0.01) {
            double along = 1.0 / (d.y + 0.08);
            vec3 p = v3(d.x * along * 1.3, 0.0, d.z * along * 1.3);
            double c = fbm(p, 5, 100u);
            double cover = smoothstep(0.52, 0.70, c) * smoothstep(0.02, 0.25, d.y);
            vec3 cloud = mix3(v3(0.92, 0.92, 0.95), v3(0.62, 0.64, 0.70), smoothstep(0.62, 0.85, c));
            colour = mix3(colour, cloud, 0.85 * cover);
        }
    } else {
        /* The ground: a field pattern on a plane below, darker straight down, hazy near the
         * horizon. */
        double along = 1.0 / (-d.y + 0.02);
        vec3 p = v3(d.x * along * 2.0, 7.5, d.z * along * 2.0);
        double fields = fbm(p, 4, 200u);
        colour = mix3(ground_near, ground_far, smoothstep(0.0, 0.8, -d.y));
        colour = scale(colour, 0.75 + 0.5 * fields);
        colour = mix3(haze, colour, smoothstep(0.0, 0.10, -d.y));
    }
    /* A warm haze band at the horizon. */
    double band = exp(-fabs(d.y) * 25.0);
    colour = mix3(colour, v3(0.80, 0.80, 0.78), 0.35 * band);

    /* The sun: a glow around it and a disk of about 1.7 degrees. */
    double c = dot(d, sun);
    if (c > 0.0) {
        double glow = 0.65 * pow(c, 300.0) + 0.25 * pow(c, 24.0) + 0.08 * pow(c, 4.0);
        colour = add(colour, scale(v3(1.0, 0.85, 0.6), glow));
        double disk = smoothstep(cos(0.95 * PI / 180.0), cos(0.75 * PI / 180.0), c);
        colour = mix3(colour, v3(1.0, 0.98, 0.92), disk);
    }
    return colour;
}

/* The direction of face f's pixel at (s, t) in [-1, 1] (s right, t down), per OpenGL. */
static vec3 cube_direction(int face, double s, double t)
{
    switch (face) {
    case 0: return v3(1.0, -t, -s);   /* +X */
    case 1: return v3(-1.0, -t, s);   /* -X */
    case 2: return v3(s, 1.0, t);     /* +Y */
    case 3: return v3(s, -1.0, -t);   /* -Y */
    case 4: return v3(s, -t, 1.0);    /* +Z */
    default: return v3(-s, -t, -1.0); /* -Z */
    }
}

static void write_sky_box(void)
{
    static const char *const names[6] = {"skybox/px.ppm", "skybox/nx.ppm", "skybox/py.ppm",
                                         "skybox/ny.ppm", "skybox/pz.ppm", "skybox/nz.ppm"};
    unsigned char *rgb = malloc((size_t)SKY_SIZE * SKY_SIZE * 3);
    if (rgb == NULL) {
        fprintf(stderr, "assets: out of memory\n");
        exit(1);
    }
    for (int face = 0; face < 6; face++) {
        for (int row = 0; row < SKY_SIZE; row++)
            for (int column = 0; column < SKY_SIZE; column++) {
                double s = 2.0 * (column + 0.5) / SKY_SIZE - 1.0;
                double t = 2.0 * (row + 0.5) / SKY_SIZE - 1.0;
                vec3 colour = sky_colour(normalize(cube_direction(face, s, t)));
                unsigned char *out = &rgb[((size_t)row * SKY_SIZE + (size_t)column) * 3];
                out[0] = srgb8(colour.x);
                out[1] = srgb8(colour.y);
                out[2] = srgb8(colour.z);
            }
        write_ppm(names[face], SKY_SIZE, SKY_SIZE, rgb);
    }
    free(rgb);
}

/* ------------------------------------------------------------------ the planet */

static vec3 earth_colour(vec3 p)
{
    /* Elevation: large continents plus detail; sea level at 0. */
    double e = fbm(scale(p, 1.6), 7, 300u) - 0.53;
    double moisture = fbm(add(scale(p, 2.5), v3(3.1, 7.7, 1.9)), 4, 400u);
    double latitude = fabs(p.y);      /* 0 at the equator, 1 at the poles */
    vec3 colour;
    if (e < 0.0) {
        double depth = smoothstep(0.0, 0.05, -e);
        colour = mix3(v3(0.05, 0.24, 0.40), v3(0.01, 0.05, 0.18), depth);
    } else {
        vec3 lowland = v3(0.10, 0.28, 0.06);
        vec3 dry = v3(0.58, 0.46, 0.25);
        vec3 highland = v3(0.30, 0.24, 0.14);
        vec3 rock = v3(0.36, 0.34, 0.32);
        /* Deserts around the subtropics where it is dry. */
        double desert = smoothstep(0.48, 0.38, moisture) * smoothstep(0.75, 0.3, latitude);
        colour = mix3(lowland, dry, desert);
        colour = mix3(colour, highland, smoothstep(0.07, 0.13, e));
        colour = mix3(colour, rock, smoothstep(0.13, 0.18, e));
        colour = mix3(colour, v3(0.85, 0.86, 0.88), smoothstep(0.20, 0.22, e));   /* peaks */
        colour = mix3(colour, v3(0.09, 0.14, 0.07), 0.5 * smoothstep(0.55, 0.95, latitude)); /* taiga */
    }
    /* Polar caps, with a ragged edge. */
    double ice_line = 0.95 + 0.06 * (fbm(scale(p, 4.0), 4, 500u) - 0.5);
    double ice = smoothstep(ice_line - 0.015, ice_line + 0.015, latitude);
    return mix3(colour, v3(0.86, 0.89, 0.93), ice);
}

static void write_earth(void)
{
    unsigned char *rgb = malloc((size_t)EARTH_WIDTH * EARTH_HEIGHT * 3);
    if (rgb == NULL) {
        fprintf(stderr, "assets: out of memory\n");
        exit(1);
    }
    for (int row = 0; row < EARTH_HEIGHT; row++)
        for (int column = 0; column < EARTH_WIDTH; column++) {
            double u = (column + 0.5) / EARTH_WIDTH, v = (row + 0.5) / EARTH_HEIGHT;
            double phi = 2.0 * PI * (u - 0.5);
            double y = cos(PI * v), r = sin(PI * v);
            vec3 p = v3(r * cos(phi), y, -r * sin(phi));
            vec3 colour = earth_colour(p);
            unsigned char *out = &rgb[((size_t)row * EARTH_WIDTH + (size_t)column) * 3];
            out[0] = srgb8(colour.x);
            out[1] = srgb8(colour.y);
            out[2] = srgb8(colour.z);
        }
    write_ppm("earth.ppm", EARTH_WIDTH, EARTH_HEIGHT, rgb);
    free(rgb);
}

/* ------------------------------------------------------------------ the normal map */

static void write_bumps(void)
{
    const double cell = (double)BUMPS_SIZE / BUMPS_CELLS;   /* 32 pixels */
    const double radius = 0.42 * cell;                      /* bump radius in pixels */
    const double height = 0.55 * radius;                    /* bump height in pixels */
    unsigned char *rgb = malloc((size_t)BUMPS_SIZE * BUMPS_SIZE * 3);
    if (rgb == NULL) {
        fprintf(stderr, "assets: out of memory\n");
        exit(1);
    }
    for (int row = 0; row < BUMPS_SIZE; row++)
        for (int column = 0; column < BUMPS_SIZE; column++) {
            /* Offset from the centre of this pixel's cell; x right, y up in the image. */
            double x = fmod(column + 0.5, cell) - 0.5 * cell;
            double y = -(fmod(row + 0.5, cell) - 0.5 * cell);
            double d = sqrt(x * x + y * y);
            /* Height h(d) = height * (1 + cos(pi d / radius)) / 2 inside the radius: a smooth
             * round bump whose slope is zero at its top and at its edge. */
            double dh_dx = 0.0, dh_dy = 0.0;
            if (d < radius && d > 0.0) {
                double dh_dd = -height * 0.5 * PI / radius * sin(PI * d / radius);
                dh_dx = dh_dd * x / d;
                dh_dy = dh_dd * y / d;
            }
            vec3 n = normalize(v3(-dh_dx, -dh_dy, 1.0));
            unsigned char *out = &rgb[((size_t)row * BUMPS_SIZE + (size_t)column) * 3];
            out[0] = raw8(n.x * 0.5 + 0.5);
            out[1] = raw8(n.y * 0.5 + 0.5);
            out[2] = raw8(n.z * 0.5 + 0.5);
        }
    write_ppm("bumps.ppm", BUMPS_SIZE, BUMPS_SIZE, rgb);
    free(rgb);
}

/* ------------------------------------------------------------------ icospheres */

typedef struct mesh {
    vec3 *positions;
    int position_count, position_capacity;
    int (*triangles)[3];
    int triangle_count;
} mesh;

static void *checked_realloc(void *p, size_t size)
{
    void *q = realloc(p, size);
    if (q == NULL) {
        fprintf(stderr, "assets: out of memory\n");
        exit(1);
    }
    return q;
}

static int add_position(mesh *m, vec3 p)
{
    if (m->position_count == m->position_capacity) {
        m->position_capacity = m->position_capacity ? 2 * m->position_capacity : 64;
        m->positions = checked_realloc(m->positions, (size_t)m->position_capacity * sizeof *m->positions);
    }
    m->positions[m->position_count] = p;
    return m->position_count++;
}

/* An open-addressing table from an edge (two position indices) to its midpoint's index. */
typedef struct edge_table {
    uint64_t *keys;     /* (low << 32 | high) + 1; 0 is empty */
    int *values;
    size_t capacity;    /* a power of two */
} edge_table;

static int midpoint(mesh *m, edge_table *table, int a, int b)
{
    uint32_t low = (uint32_t)(a < b ? a : b), high = (uint32_t)(a < b ? b : a);
    uint64_t key = (((uint64_t)low << 32) | high) + 1;
    size_t slot = (size_t)hash32(low * 0x9e3779b9u ^ hash32(high)) & (table->capacity - 1);
    while (table->keys[slot] != 0) {
        if (table->keys[slot] == key)
            return table->values[slot];
        slot = (slot + 1) & (table->capacity - 1);
    }
    vec3 p = normalize(scale(add(m->positions[a], m->positions[b]), 0.5));
    table->keys[slot] = key;
    table->values[slot] = add_position(m, p);
    return table->values[slot];
}

/* A unit icosphere: the icosahedron, each triangle split into 4 `level` times, every new
 * position pushed out onto the unit sphere. Triangles are counter-clockwise from outside. */
static mesh icosphere(int level)
{
    mesh m = {0};
    const double g = (1.0 + sqrt(5.0)) / 2.0;
    const double corners[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                   {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                   {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    static const int faces[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
                                     {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                     {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8}, {3, 8, 9},
                                     {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (int i = 0; i < 12; i++)
        add_position(&m, normalize(v3(corners[i][0], corners[i][1], corners[i][2])));
    m.triangles = checked_realloc(NULL, sizeof faces);
    memcpy(m.triangles, faces, sizeof faces);
    m.triangle_count = 20;

    for (int l = 0; l < level; l++) {
        edge_table table;
        size_t edges = (size_t)m.triangle_count * 3 / 2;
        table.capacity = 64;
        while (table.capacity < 2 * edges)
            table.capacity *= 2;
        table.keys = calloc(table.capacity, sizeof *table.keys);
        table.values = calloc(table.capacity, sizeof *table.values);
        if (table.keys == NULL || table.values == NULL) {
            fprintf(stderr, "assets: out of memory\n");
            exit(1);
        }
        int (*next)[3] = checked_realloc(NULL, (size_t)m.triangle_count * 4 * sizeof *next);
        for (int t = 0; t < m.triangle_count; t++) {
            int a = m.triangles[t][0], b = m.triangles[t][1], c = m.triangles[t][2];
            int ab = midpoint(&m, &table, a, b), bc = midpoint(&m, &table, b, c),
                ca = midpoint(&m, &table, c, a);
            int *n = next[4 * t];
            n[0] = a, n[1] = ab, n[2] = ca;
            n = next[4 * t + 1];
            n[0] = b, n[1] = bc, n[2] = ab;
            n = next[4 * t + 2];
            n[0] = c, n[1] = ca, n[2] = bc;
            n = next[4 * t + 3];
            n[0] = ab, n[1] = bc, n[2] = ca;
        }
        free(table.keys);
        free(table.values);
        free(m.triangles);
        m.triangles = next;
        m.triangle_count *= 4;
    }
    return m;
}

/* Writes m as OBJ: positions, vn (when smooth: the unit position), vt (spherical, seam
 * fixed per triangle) and faces. */
static void write_icosphere_obj(const char *name, const mesh *m, int smooth, const char *comment)
{
    char path[4096];
    FILE *f = open_output(name, path, sizeof path);
    int n = m->position_count;
    /* vt: one per position, u in [0, 1), plus a copy with u + 1 for positions used by
     * triangles that cross the u seam, added when first needed. */
    double *u = checked_realloc(NULL, (size_t)n * sizeof *u);
    double *v = checked_realloc(NULL, (size_t)n * sizeof *v);
    int *wrapped = checked_realloc(NULL, (size_t)n * sizeof *wrapped);
    int *wrapped_of = checked_realloc(NULL, (size_t)n * sizeof *wrapped_of);
    int wrapped_count = 0;
    for (int i = 0; i < n; i++) {
        vec3 p = m->positions[i];
        u[i] = 0.5 + atan2(-p.z, p.x) / (2.0 * PI);
        if (u[i] >= 1.0)
            u[i] -= 1.0;
        v[i] = 0.5 + asin(p.y < -1.0 ? -1.0 : p.y > 1.0 ? 1.0 : p.y) / PI;
        wrapped[i] = -1;
    }
    int (*tex)[3] = checked_realloc(NULL, (size_t)m->triangle_count * sizeof *tex);
    for (int t = 0; t < m->triangle_count; t++) {
        const int *tri = m->triangles[t];
        double lo = 1.0, hi = 0.0;
        for (int k = 0; k < 3; k++) {
            lo = u[tri[k]] < lo ? u[tri[k]] : lo;
            hi = u[tri[k]] > hi ? u[tri[k]] : hi;
        }
        for (int k = 0; k < 3; k++) {
            int p = tri[k];
            if (hi - lo > 0.5 && u[p] < 0.5) {
                if (wrapped[p] < 0) {
                    wrapped_of[wrapped_count] = p;
                    wrapped[p] = n + wrapped_count++;
                }
                tex[t][k] = wrapped[p];
            } else {
                tex[t][k] = p;
            }
        }
    }

    fprintf(f, "# %s: %s\n", name, comment);
    fprintf(f, "# Written by scenes/generators/assets.c: %d positions, %d triangles, radius 1,\n"
               "# centred at the origin; vt spherical (v = 1 at the top)%s.\n",
            n, m->triangle_count, smooth ? ", vn the unit position (smooth)" : ", no vn (flat facets)");
    for (int i = 0; i < n; i++)
        fprintf(f, "v %.6f %.6f %.6f\n", m->positions[i].x, m->positions[i].y, m->positions[i].z);
    if (smooth)
        for (int i = 0; i < n; i++)
            fprintf(f, "vn %.6f %.6f %.6f\n", m->positions[i].x, m->positions[i].y, m->positions[i].z);
    for (int i = 0; i < n; i++)
        fprintf(f, "vt %.6f %.6f\n", u[i], v[i]);
    for (int i = 0; i < wrapped_count; i++)
        fprintf(f, "vt %.6f %.6f\n", u[wrapped_of[i]] + 1.0, v[wrapped_of[i]]);
    for (int t = 0; t < m->triangle_count; t++) {
        const int *tri = m->triangles[t];
        if (smooth)
            fprintf(f, "f %d/%d/%d %d/%d/%d %d/%d/%d\n", tri[0] + 1, tex[t][0] + 1, tri[0] + 1,
                    tri[1] + 1, tex[t][1] + 1, tri[1] + 1, tri[2] + 1, tex[t][2] + 1, tri[2] + 1);
        else
            fprintf(f, "f %d/%d %d/%d %d/%d\n", tri[0] + 1, tex[t][0] + 1, tri[1] + 1,
                    tex[t][1] + 1, tri[2] + 1, tex[t][2] + 1);
    }
    free(u);
    free(v);
    free(wrapped);
    free(wrapped_of);
    free(tex);
    close_output(f, path);
}

static void free_mesh(mesh *m)
{
    free(m->positions);
    free(m->triangles);
}

/* ------------------------------------------------------------------ the stand */

/* The stand's profile, a closed outline turned about the y axis: (radius, height) points
 * from the bottom centre round to the bottom of the cup. Consecutive points make one part,
 * a ring of STAND_SIDES faces (quads, or triangles where a point is on the axis); each part
 * has its own normals, so the edges between parts are hard. */
static const double stand_profile[][2] = {
    {0.0, 0.0},                         /* bottom centre */
    {0.85, 0.0},                        /* bottom: a flat octagon */
    {0.85, 0.08},                       /* foot: a vertical band */
    {0.42, 0.30},                       /* stem: tapering in */
    {STAND_TOP_RADIUS, STAND_HEIGHT},   /* collar: flaring out to the rim */
    {0.0, STAND_CUP_BOTTOM},            /* cup: a shallow cone down to the axis */
};

static void write_stand(void)
{
    char path[4096];
    FILE *f = open_output("stand.obj", path, sizeof path);
    const int sides = STAND_SIDES;
    const int points = (int)(sizeof stand_profile / sizeof stand_profile[0]);
    fprintf(f, "# stand.obj: an octagonal pedestal for the crystal ball (crystal.obj).\n"
               "# Written by scenes/generators/assets.c. Base at y = 0, rim of radius %.2f (at the\n"
               "# octagon's corners) at y = %.2f, a cup-shaped top. A unit sphere resting on the rim\n"
               "# has its centre at y = %.4f; put crystal.obj (as written) at y = %.4f.\n"
               "# Parts (each a ring of %d faces): bottom, foot band, tapered stem, collar, cup.\n"
               "# vn: smooth around the octagon, hard between parts.\n",
            STAND_TOP_RADIUS, STAND_HEIGHT,
            STAND_HEIGHT + sqrt(1.0 - STAND_TOP_RADIUS * STAND_TOP_RADIUS), CRYSTAL_REST_Y, sides);

    /* Positions: profile point r, corner k; a point on the axis is one position. */
    int first[16];
    int count = 0;
    for (int r = 0; r < points; r++) {
        first[r] = count + 1;
        double radius = stand_profile[r][0], y = stand_profile[r][1];
        if (radius == 0.0) {
            fprintf(f, "v 0 %.6f 0\n", y);
            count += 1;
        } else {
            for (int k = 0; k < sides; k++) {
                /* Rotated by half a side so that a flat side faces +Z and -Z. */
                double a = 2.0 * PI * (k + 0.5) / sides;
                fprintf(f, "v %.6f %.6f %.6f\n", radius * cos(a), y, -radius * sin(a));
            }
            count += sides;
        }
    }
    /* vt: u around, v along the profile. */
    for (int r = 0; r < points; r++)
        for (int k = 0; k <= sides; k++)
            fprintf(f, "vt %.6f %.6f\n", (double)k / sides, (double)r / (points - 1));

    /* Normals and faces, part by part. Corner k of a part has the normal perpendicular to
     * the profile segment, turned to corner k's direction. Faces are counter-clockwise
     * seen from outside: (r, k), (r, k+1), (r+1, k+1), (r+1, k), without the repeated
     * corner where a point is on the axis. */
    int normal = 0;
    for (int r = 0; r + 1 < points; r++) {
        double r0 = stand_profile[r][0], y0 = stand_profile[r][1];
        double r1 = stand_profile[r + 1][0], y1 = stand_profile[r + 1][1];
        double dr = r1 - r0, dy = y1 - y0;
        double length = sqrt(dr * dr + dy * dy);
        double nr = dy / length, ny = -dr / length;
        fprintf(f, "# part %d\n", r + 1);
        int base = normal;
        for (int k = 0; k < sides; k++) {
            double a = 2.0 * PI * (k + 0.5) / sides;
            fprintf(f, "vn %.6f %.6f %.6f\n", nr * cos(a) + 0.0, ny + 0.0, -nr * sin(a) + 0.0);
        }
        normal += sides;
        for (int k = 0; k < sides; k++) {
            int k1 = (k + 1) % sides;
            int corner[4][3] = {
                {r0 == 0.0 ? first[r] : first[r] + k, r * (sides + 1) + k + 1, base + k + 1},
                {r0 == 0.0 ? first[r] : first[r] + k1, r * (sides + 1) + k + 2, base + k1 + 1},
                {r1 == 0.0 ? first[r + 1] : first[r + 1] + k1, (r + 1) * (sides + 1) + k + 2, base + k1 + 1},
                {r1 == 0.0 ? first[r + 1] : first[r + 1] + k, (r + 1) * (sides + 1) + k + 1, base + k + 1},
            };
            fprintf(f, "f");
            for (int c = 0; c < 4; c++) {
                if ((c == 1 && r0 == 0.0) || (c == 3 && r1 == 0.0))
                    continue;   /* the axis point, already written */
                fprintf(f, " %d/%d/%d", corner[c][0], corner[c][1], corner[c][2]);
            }
            fprintf(f, "\n");
        }
    }
    close_output(f, path);
}

/* ------------------------------------------------------------------ main */

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3) {
        fprintf(stderr, "usage: %s DIR        write every asset of scenes/ into DIR\n"
                        "       %s DIR N      write only DIR/icosphere-N.obj (N = 0 .. 9)\n",
                argv[0], argv[0]);
        return 2;
    }
    output_directory = argv[1];
    make_directory(output_directory);

    if (argc == 3) {
        char *end;
        long level = strtol(argv[2], &end, 10);
        if (*argv[2] == '\0' || *end != '\0' || level < 0 || level > 9) {
            fprintf(stderr, "assets: the subdivision level must be a whole number 0 .. 9, not '%s'\n",
                    argv[2]);
            return 2;
        }
        char name[64], comment[128];
        snprintf(name, sizeof name, "icosphere-%ld.obj", level);
        snprintf(comment, sizeof comment, "an icosphere of subdivision %ld", level);
        mesh m = icosphere((int)level);
        write_icosphere_obj(name, &m, 1, comment);
        free_mesh(&m);
        return 0;
    }

    char skybox[4096];
    snprintf(skybox, sizeof skybox, "%s/skybox", output_directory);
    make_directory(skybox);
    write_sky_box();
    write_earth();
    write_bumps();
    mesh crystal = icosphere(1);
    write_icosphere_obj("crystal.obj", &crystal, 0, "a faceted crystal ball (icosphere, subdivision 1)");
    free_mesh(&crystal);
    write_stand();
    return 0;
}
