/* ply_load.c: see ply_load.h. The file is read into memory whole, its header parsed into
 * elements and properties, then the data read element by element, each property by its
 * declared type, the ones the mesh needs kept by their role. */
#include "ply_load.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "array.h"

/* Longest element or property name kept (longer names are cut in messages only). */
#define NAME_MAX_BYTES 64
#define REASON_MAX 600

typedef enum value_type {
    TYPE_CHAR, TYPE_UCHAR, TYPE_SHORT, TYPE_USHORT, TYPE_INT, TYPE_UINT, TYPE_FLOAT, TYPE_DOUBLE, TYPE_COUNT,
} value_type;

/* The value types, with both spellings the format allows, their sizes and ranges. */
static const struct {
    const char *name, *alias;
    int size;
    bool is_float;
    double low, high;
} types[TYPE_COUNT] = {
    {"char", "int8", 1, false, -128.0, 127.0},
    {"uchar", "uint8", 1, false, 0.0, 255.0},
    {"short", "int16", 2, false, -32768.0, 32767.0},
    {"ushort", "uint16", 2, false, 0.0, 65535.0},
    {"int", "int32", 4, false, -2147483648.0, 2147483647.0},
    {"uint", "uint32", 4, false, 0.0, 4294967295.0},
    {"float", "float32", 4, true, -INFINITY, INFINITY},
    {"double", "float64", 8, true, -INFINITY, INFINITY},
};

/* What a property is to the mesh. */
typedef enum role {
    ROLE_NONE, ROLE_X, ROLE_Y, ROLE_Z, ROLE_NX, ROLE_NY, ROLE_NZ, ROLE_U, ROLE_V,
    ROLE_RED, ROLE_GREEN, ROLE_BLUE, ROLE_INDICES, ROLE_COUNT,
} role;

typedef struct ply_property {
    char name[NAME_MAX_BYTES];
    value_type type;             /* a list's item type */
    bool is_list;
    value_type count_type;       /* lists only */
    role role;
} ply_property;

typedef enum element_kind { ELEMENT_OTHER, ELEMENT_VERTEX, ELEMENT_FACE } element_kind;

typedef struct ply_element {
    char name[NAME_MAX_BYTES];
    long long count;
    element_kind kind;
    ply_property *properties;
    int property_count;
    size_t property_capacity;
} ply_element;

typedef enum data_format { FORMAT_ASCII, FORMAT_LITTLE_ENDIAN, FORMAT_BIG_ENDIAN } data_format;

/* One read in progress: the bytes, where it is, what the header declared, what is kept. */
typedef struct reader {
    const unsigned char *data;
    size_t size, at;
    int line;                    /* ASCII: the line of `at` (1-based, counting the header) */
    data_format format;
    ply_element *elements;
    int element_count;
    size_t element_capacity;
    int vertex_element, face_element;  /* indices into elements, or -1 */
    bool has_normals, has_uvs, has_colors;
    ply_mesh *out;
    size_t index_capacity;       /* of out->indices, in uint32 */
    bool out_of_memory;
    char reason[REASON_MAX];
} reader;

/* Records why the file cannot be read (the first reason wins); returns false. */
static bool fail(reader *r, const char *format, ...) __attribute__((format(printf, 2, 3)));
static bool fail(reader *r, const char *format, ...)
{
    if (r->reason[0] != '\0')
        return false;
    va_list arguments;
    va_start(arguments, format);
    vsnprintf(r->reason, sizeof r->reason, format, arguments);
    va_end(arguments);
    return false;
}

/* Records that memory ran out; returns false. */
static bool fail_memory(reader *r)
{
    r->out_of_memory = true;
    return fail(r, "out of memory");
}

/* ------------------------------------------------------------------ the header */

/* Splits line (NUL-terminated, changed in place) into at most max words at spaces and
 * tabs; returns how many. */
static int split_words(char *line, char **words, int max)
{
    int count = 0;
    char *p = line;
    while (*p != '\0' && count < max) {
        while (*p == ' ' || *p == '\t')
            p++;
        if (*p == '\0')
            break;
        words[count++] = p;
        while (*p != '\0' && *p != ' ' && *p != '\t')
            p++;
        if (*p != '\0')
            *p++ = '\0';
    }
    return count;
}

/* Sets *type to the value type called name; false when there is none. */
static bool type_named(const char *name, value_type *type)
{
    for (int t = 0; t < TYPE_COUNT; t++)
        if (strcmp(name, types[t].name) == 0 || strcmp(name, types[t].alias) == 0) {
            *type = (value_type)t;
            return true;
        }
    return false;
}

/* The role of a property called name of an element of kind (ROLE_NONE: skipped). */
static role role_of(element_kind kind, const char *name)
{
    static const struct {
        const char *name;
        role role;
    } vertex_roles[] = {
        {"x", ROLE_X}, {"y", ROLE_Y}, {"z", ROLE_Z}, {"nx", ROLE_NX}, {"ny", ROLE_NY}, {"nz", ROLE_NZ},
        {"s", ROLE_U}, {"t", ROLE_V}, {"u", ROLE_U}, {"v", ROLE_V}, {"texture_u", ROLE_U}, {"texture_v", ROLE_V},
        {"texture_s", ROLE_U}, {"texture_t", ROLE_V}, {"red", ROLE_RED}, {"green", ROLE_GREEN}, {"blue", ROLE_BLUE},
    };
    if (kind == ELEMENT_FACE)
        return strcmp(name, "vertex_indices") == 0 || strcmp(name, "vertex_index") == 0 ? ROLE_INDICES : ROLE_NONE;
    if (kind != ELEMENT_VERTEX)
        return ROLE_NONE;
    for (size_t i = 0; i < sizeof vertex_roles / sizeof vertex_roles[0]; i++)
        if (strcmp(name, vertex_roles[i].name) == 0)
            return vertex_roles[i].role;
    return ROLE_NONE;
}

/* Reads "element NAME COUNT" (words) at line. */
static bool header_element(reader *r, char **words, int count, int line)
{
    if (count != 3)
        return fail(r, "line %d: expected 'element NAME COUNT'", line);
    char *end = NULL;
    errno = 0;
    long long elements = strtoll(words[2], &end, 10);
    if (end == words[2] || *end != '\0' || errno != 0 || elements < 0 || elements > INT_MAX)
        return fail(r, "line %d: the count of element '%.64s' must be a whole number from 0 to 2147483647, found "
                    "'%.40s'", line, words[1], words[2]);
    for (int e = 0; e < r->element_count; e++)
        if (strcmp(r->elements[e].name, words[1]) == 0)
            return fail(r, "line %d: element '%.64s' is declared twice", line, words[1]);
    if (!array_reserve((void **)&r->elements, &r->element_capacity, (size_t)r->element_count + 1,
                       sizeof *r->elements))
        return fail_memory(r);
    ply_element *element = &r->elements[r->element_count];
    memset(element, 0, sizeof *element);
    snprintf(element->name, sizeof element->name, "%s", words[1]);
    element->count = elements;
    element->kind = strcmp(words[1], "vertex") == 0 ? ELEMENT_VERTEX
                    : strcmp(words[1], "face") == 0 ? ELEMENT_FACE : ELEMENT_OTHER;
    if (element->kind == ELEMENT_VERTEX)
        r->vertex_element = r->element_count;
    if (element->kind == ELEMENT_FACE)
        r->face_element = r->element_count;
    r->element_count++;
    return true;
}

/* Reads "property TYPE NAME" or "property list COUNT_TYPE ITEM_TYPE NAME" at line. */
static bool header_property(reader *r, char **words, int count, int line)
{
    if (r->element_count == 0)
        return fail(r, "line %d: a property before any element", line);
    ply_element *element = &r->elements[r->element_count - 1];
    ply_property property = {.role = ROLE_NONE};
    bool is_list = count >= 2 && strcmp(words[1], "list") == 0;
    if (is_list ? count != 5 : count != 3)
        return fail(r, "line %d: expected 'property TYPE NAME' or 'property list COUNT_TYPE ITEM_TYPE NAME'", line);
    const char *name = words[count - 1];
    property.is_list = is_list;
    if (is_list && !type_named(words[2], &property.count_type))
        return fail(r, "line %d: unknown type '%.40s' of the count of property '%.64s'", line, words[2], name);
    if (is_list && types[property.count_type].is_float)
        return fail(r, "line %d: the count of list property '%.64s' has the float type '%s'", line, name,
                    types[property.count_type].name);
    if (!type_named(words[count - 2], &property.type))
        return fail(r, "line %d: unknown type '%.40s' of property '%.64s'", line, words[count - 2], name);
    snprintf(property.name, sizeof property.name, "%s", name);
    property.role = role_of(element->kind, name);
    for (int p = 0; p < element->property_count; p++) {
        if (strcmp(element->properties[p].name, property.name) == 0)
            return fail(r, "line %d: element '%s' has property '%.64s' twice", line, element->name, name);
        /* Only the first texture coordinate pair (s t, u v, ...) or index list counts. */
        if (property.role != ROLE_NONE && element->properties[p].role == property.role)
            property.role = ROLE_NONE;
    }
    if (property.role == ROLE_INDICES && (!is_list || types[property.type].is_float))
        return fail(r, "line %d: the face property '%.64s' must be a list of whole numbers", line, name);
    if (property.role != ROLE_NONE && property.role != ROLE_INDICES && is_list)
        return fail(r, "line %d: the vertex property '%.64s' is a list; it must be one number", line, name);
    if (!array_reserve((void **)&element->properties, &element->property_capacity,
                       (size_t)element->property_count + 1, sizeof *element->properties))
        return fail_memory(r);
    element->properties[element->property_count++] = property;
    return true;
}

/* Returns whether element has a property of role. */
static bool has_role(const ply_element *element, role wanted)
{
    for (int p = 0; p < element->property_count; p++)
        if (element->properties[p].role == wanted)
            return true;
    return false;
}

/* Checks that the vertex and face elements have what a mesh needs; sets which optional
 * attributes it has. */
static bool check_elements(reader *r)
{
    if (r->vertex_element < 0)
        return fail(r, "the header declares no 'vertex' element");
    if (r->face_element < 0)
        return fail(r, "the header declares no 'face' element (a point cloud is not a mesh)");
    const ply_element *vertex = &r->elements[r->vertex_element];
    static const char *const axes[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; k++)
        if (!has_role(vertex, (role)(ROLE_X + k)))
            return fail(r, "the vertex element has no property '%s'", axes[k]);
    int normals = has_role(vertex, ROLE_NX) + has_role(vertex, ROLE_NY) + has_role(vertex, ROLE_NZ);
    int colors = has_role(vertex, ROLE_RED) + has_role(vertex, ROLE_GREEN) + has_role(vertex, ROLE_BLUE);
    int uvs = has_role(vertex, ROLE_U) + has_role(vertex, ROLE_V);
    if (normals != 0 && normals != 3)
        return fail(r, "the vertex element has only some of nx, ny and nz (a normal needs all three)");
    if (colors != 0 && colors != 3)
        return fail(r, "the vertex element has only some of red, green and blue (a colour needs all three)");
    if (uvs == 1)
        return fail(r, "the vertex element has only one texture coordinate (s t, u v, texture_u texture_v or "
                    "texture_s texture_t come in pairs)");
    if (!has_role(&r->elements[r->face_element], ROLE_INDICES))
        return fail(r, "the face element has no 'vertex_indices' (or 'vertex_index') list");
    r->has_normals = normals == 3;
    r->has_colors = colors == 3;
    r->has_uvs = uvs == 2;
    return true;
}

/* Parses the header; leaves r->at at the first byte of the data. */
static bool parse_header(reader *r)
{
    int line = 0;
    bool ended = false, format_seen = false;
    while (!ended) {
        if (r->at >= r->size)
            return fail(r, line == 0 ? "line 1: not a PLY file (it is empty)" : "the header has no end_header line");
        const unsigned char *start = r->data + r->at;
        const unsigned char *newline = memchr(start, '\n', r->size - r->at);
        size_t length = newline != NULL ? (size_t)(newline - start) : r->size - r->at;
        r->at += length + (newline != NULL);
        line++;
        if (length > 0 && start[length - 1] == '\r')
            length--;
        char text[1024];
        if (length >= sizeof text)
            return fail(r, "line %d: a header line longer than %zu bytes", line, sizeof text - 1);
        if (memchr(start, '\0', length) != NULL)
            return fail(r, line == 1 ? "line 1: not a PLY file (it does not start with a 'ply' line)"
                                     : "line %d: a NUL byte in the header", line);
        memcpy(text, start, length);
        text[length] = '\0';
        if (line == 1) {
            if (strcmp(text, "ply") != 0)
                return fail(r, "line 1: not a PLY file (it does not start with a 'ply' line)");
            continue;
        }
        char *words[8];
        int count = split_words(text, words, 8);
        if (count == 0 || strcmp(words[0], "comment") == 0 || strcmp(words[0], "obj_info") == 0)
            continue;
        if (!format_seen) {
            if (strcmp(words[0], "format") != 0 || count != 3)
                return fail(r, "line %d: expected 'format ascii 1.0' (or binary_little_endian, binary_big_endian) "
                            "after the 'ply' line", line);
            if (strcmp(words[1], "ascii") == 0)
                r->format = FORMAT_ASCII;
            else if (strcmp(words[1], "binary_little_endian") == 0)
                r->format = FORMAT_LITTLE_ENDIAN;
            else if (strcmp(words[1], "binary_big_endian") == 0)
                r->format = FORMAT_BIG_ENDIAN;
            else
                return fail(r, "line %d: unknown format '%.40s' (expected ascii, binary_little_endian or "
                            "binary_big_endian)", line, words[1]);
            if (strcmp(words[2], "1.0") != 0)
                return fail(r, "line %d: unknown format version '%.40s' (expected 1.0)", line, words[2]);
            format_seen = true;
            continue;
        }
        if (strcmp(words[0], "element") == 0) {
            if (!header_element(r, words, count, line))
                return false;
        } else if (strcmp(words[0], "property") == 0) {
            if (!header_property(r, words, count, line))
                return false;
        } else if (strcmp(words[0], "end_header") == 0 && count == 1) {
            ended = true;
        } else {
            return fail(r, "line %d: unknown header line '%.40s' (expected element, property, comment, obj_info or "
                        "end_header)", line, words[0]);
        }
    }
    r->line = line + 1;
    return check_elements(r);
}

/* ------------------------------------------------------------------ values */

/* Whether c separates ASCII values (a NUL byte does not: it is refused inside a value). */
static bool is_space(unsigned char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

/* Moves past white space, counting lines. */
static void skip_space(reader *r)
{
    while (r->at < r->size && is_space(r->data[r->at])) {
        r->line += r->data[r->at] == '\n';
        r->at++;
    }
}

/* Reads one binary value of type into *value; false at the end of the data. */
static bool read_binary(reader *r, value_type type, double *value)
{
    int size = types[type].size;
    if (r->size - r->at < (size_t)size)
        return false;
    unsigned char bytes[8];
    for (int i = 0; i < size; i++)
        bytes[i] = r->data[r->at + (size_t)(r->format == FORMAT_BIG_ENDIAN ? size - 1 - i : i)];
    r->at += (size_t)size;
    /* bytes now holds the value least significant byte first. */
    uint64_t bits = 0;
    for (int i = size - 1; i >= 0; i--)
        bits = bits << 8 | bytes[i];
    switch (type) {
    case TYPE_CHAR: *value = (int8_t)bits; break;
    case TYPE_SHORT: *value = (int16_t)bits; break;
    case TYPE_INT: *value = (int32_t)bits; break;
    case TYPE_FLOAT: {
        uint32_t word = (uint32_t)bits;
        float f;
        memcpy(&f, &word, sizeof f);
        *value = f;
        break;
    }
    case TYPE_DOUBLE: memcpy(value, &bits, sizeof *value); break;
    default: *value = (double)bits; break;   /* the unsigned types */
    }
    return true;
}

/* Names a value in messages: "'x' of vertex 12". */
typedef struct value_place {
    const ply_element *element;
    long long record;
    const char *property;
} value_place;

/* Reads one ASCII number of type into *value; false at the end of the data (no reason) or
 * on a bad number (a reason naming place). */
static bool read_ascii(reader *r, value_type type, double *value, const value_place *place)
{
    skip_space(r);
    if (r->at >= r->size)
        return false;
    char token[64];
    size_t length = 0;
    while (r->at + length < r->size && !is_space(r->data[r->at + length]))
        length++;
    const char *element = place->element->name, *property = place->property;
    if (memchr(r->data + r->at, '\0', length) != NULL)
        return fail(r, "line %d: a NUL byte in '%s' of %s %lld", r->line, property, element, place->record);
    if (length >= sizeof token)
        return fail(r, "line %d: expected a number for '%s' of %s %lld, found '%.40s...'", r->line, property,
                    element, place->record, (const char *)r->data + r->at);
    memcpy(token, r->data + r->at, length);
    token[length] = '\0';
    char *end = NULL;
    errno = 0;
    if (types[type].is_float) {
        *value = strtod(token, &end);
        if (end == token || *end != '\0')
            return fail(r, "line %d: expected a number for '%s' of %s %lld, found '%s'", r->line, property, element,
                        place->record, token);
    } else {
        long long whole = strtoll(token, &end, 10);
        if (end == token || *end != '\0' || errno != 0)
            return fail(r, "line %d: expected a whole number for '%s' of %s %lld (its type is %s), found '%s'",
                        r->line, property, element, place->record, types[type].name, token);
        if (whole < types[type].low || whole > types[type].high)
            return fail(r, "line %d: the value %s of '%s' of %s %lld does not fit its type %s", r->line, token,
                        property, element, place->record, types[type].name);
        *value = (double)whole;
    }
    r->at += length;
    return true;
}

/* Reads one value of type, at place (for messages). */
static bool read_value(reader *r, value_type type, double *value, const ply_element *element, long long record,
                       const char *property)
{
    value_place place = {element, record, property};
    bool ok = r->format == FORMAT_ASCII ? read_ascii(r, type, value, &place) : read_binary(r, type, value);
    if (!ok && r->reason[0] == '\0')
        fail(r, "the data ends inside %s %lld (the header declares %lld)", element->name, record, element->count);
    return ok;
}

/* ------------------------------------------------------------------ the data */

/* The fewest bytes one record of element can take in the data (for the size check). */
static size_t smallest_record(const reader *r, const ply_element *element)
{
    size_t bytes = 0;
    for (int p = 0; p < element->property_count; p++) {
        const ply_property *property = &element->properties[p];
        /* ASCII: a digit and a separator per value; binary: the value's (or count's) size. */
        bytes += r->format == FORMAT_ASCII ? 2 : (size_t)types[property->is_list ? property->count_type
                                                                                   : property->type].size;
    }
    return bytes;
}

/* Allocates the vertex arrays the header asks for. */
static bool allocate_vertices(reader *r, long long count)
{
    ply_mesh *out = r->out;
    size_t n = (size_t)count > 0 ? (size_t)count : 1;
    out->positions = malloc(3 * n * sizeof *out->positions);
    out->normals = r->has_normals ? malloc(3 * n * sizeof *out->normals) : NULL;
    out->uvs = r->has_uvs ? malloc(2 * n * sizeof *out->uvs) : NULL;
    out->colors = r->has_colors ? malloc(3 * n * sizeof *out->colors) : NULL;
    if (out->positions == NULL || (r->has_normals && out->normals == NULL) || (r->has_uvs && out->uvs == NULL) ||
        (r->has_colors && out->colors == NULL))
        return fail_memory(r);
    out->vertex_count = (int)count;
    return true;
}

/* Stores value of a vertex property of role for vertex v. */
static bool store_vertex_value(reader *r, const ply_property *property, long long v, double value)
{
    ply_mesh *out = r->out;
    role role = property->role;
    if (!isfinite(value) || fabs(value) > 3.4028234663852886e38)
        return fail(r, "vertex %lld: '%s' is not a finite number (NaN, infinite or beyond the range of a float)", v,
                    property->name);
    if (role >= ROLE_X && role <= ROLE_Z)
        out->positions[3 * v + (role - ROLE_X)] = (float)value;
    else if (role >= ROLE_NX && role <= ROLE_NZ)
        out->normals[3 * v + (role - ROLE_NX)] = (float)value;
    else if (role == ROLE_U || role == ROLE_V)
        out->uvs[2 * v + (role - ROLE_U)] = (float)value;
    else if (role >= ROLE_RED && role <= ROLE_BLUE) {
        double encoded = types[property->type].is_float ? value : value / types[property->type].high;
        out->colors[3 * v + (role - ROLE_RED)] = (float)(encoded > 1 ? 1 : encoded > 0 ? encoded : 0);
    }
    return true;
}

/* Appends the triangle fan of one face (corners: its vertex indices) to the mesh. */
static bool add_face(reader *r, long long face, const uint32_t *corners, long long corner_count)
{
    ply_mesh *out = r->out;
    if (corner_count < 3)
        return fail(r, "face %lld has %lld corner%s; a face needs at least 3", face, corner_count,
                    corner_count == 1 ? "" : "s");
    if ((long long)out->triangle_count + corner_count - 2 > INT_MAX)
        return fail(r, "more than 2^31 - 1 triangles are not supported");
    size_t needed = 3 * ((size_t)out->triangle_count + (size_t)corner_count - 2);
    if (!array_reserve((void **)&out->indices, &r->index_capacity, needed, sizeof *out->indices))
        return fail_memory(r);
    for (long long k = 1; k + 1 < corner_count; k++) {
        uint32_t *triangle = out->indices + 3 * (size_t)out->triangle_count++;
        triangle[0] = corners[0];
        triangle[1] = corners[k];
        triangle[2] = corners[k + 1];
    }
    return true;
}

/* Reads one list property of record (its items kept as corners when it is the face's
 * index list); corners grows as needed. */
static bool read_list(reader *r, const ply_element *element, long long record, const ply_property *property,
                      uint32_t **corners, size_t *corner_capacity)
{
    double count_value = 0;
    if (!read_value(r, property->count_type, &count_value, element, record, property->name))
        return false;
    if (count_value < 0)
        return fail(r, "%s %lld: the list '%s' has a negative length (%.0f)", element->name, record, property->name,
                    count_value);
    /* Every item takes at least a byte: a length beyond the data is an error, not an
     * allocation. */
    if (count_value > (double)(r->size - r->at))
        return fail(r, "the data ends inside %s %lld (its list '%s' has %.0f items)", element->name, record,
                    property->name, count_value);
    long long count = (long long)count_value;
    bool keep = property->role == ROLE_INDICES;
    if (keep && !array_reserve((void **)corners, corner_capacity, (size_t)count, sizeof **corners))
        return fail_memory(r);
    const long long vertex_count = r->elements[r->vertex_element].count;
    for (long long i = 0; i < count; i++) {
        double value = 0;
        if (!read_value(r, property->type, &value, element, record, property->name))
            return false;
        if (!keep)
            continue;
        if (value < 0 || value >= (double)vertex_count)
            return fail(r, "face %lld: vertex index %.0f is out of range: the file has %lld vertices", record, value,
                        vertex_count);
        (*corners)[i] = (uint32_t)value;
    }
    return !keep || add_face(r, record, *corners, count);
}

/* Reads every record of element e. */
static bool read_element(reader *r, int e)
{
    const ply_element *element = &r->elements[e];
    if (element->property_count == 0 || element->count == 0)
        return true;
    size_t smallest = smallest_record(r, element);
    if (smallest > 0 && (size_t)element->count > (r->size - r->at) / smallest + 1)
        return fail(r, "the data is too short for the %lld %s records the header declares (%zu bytes are left, "
                    "each record takes at least %zu)", element->count, element->name, r->size - r->at, smallest);
    if (element->kind == ELEMENT_VERTEX && !allocate_vertices(r, element->count))
        return false;
    uint32_t *corners = NULL;
    size_t corner_capacity = 0;
    bool ok = true;
    for (long long record = 0; ok && record < element->count; record++) {
        for (int p = 0; ok && p < element->property_count; p++) {
            const ply_property *property = &element->properties[p];
            if (property->is_list) {
                ok = read_list(r, element, record, property, &corners, &corner_capacity);
                continue;
            }
            double value = 0;
            ok = read_value(r, property->type, &value, element, record, property->name);
            if (ok && element->kind == ELEMENT_VERTEX && property->role != ROLE_NONE)
                ok = store_vertex_value(r, property, record, value);
        }
    }
    free(corners);
    return ok;
}

/* Checks that nothing but white space (ASCII) or nothing at all (binary) follows the data. */
static bool check_end(reader *r)
{
    if (r->format != FORMAT_ASCII) {
        if (r->at < r->size)
            return fail(r, "%zu bytes after the last element", r->size - r->at);
        return true;
    }
    skip_space(r);
    if (r->at < r->size) {
        size_t length = 0;
        while (r->at + length < r->size && length < 40 && !is_space(r->data[r->at + length]) &&
               r->data[r->at + length] != '\0')
            length++;
        return fail(r, "line %d: '%.*s' after the last element", r->line, (int)length, r->data + r->at);
    }
    return true;
}

/* Makes each normal unit length (in double: see obj_load.cpp's normalize for why), zero
 * staying zero. */
static void normalize_normals(ply_mesh *out)
{
    for (int v = 0; out->normals != NULL && v < out->vertex_count; v++) {
        float *n = out->normals + 3 * (size_t)v;
        double x = n[0], y = n[1], z = n[2], length = sqrt(x * x + y * y + z * z);
        for (int k = 0; k < 3; k++)
            n[k] = length > 0 && isfinite(length) ? (float)(n[k] / length) : 0.0f;
    }
}

/* Reads the whole file (header, every element, the end) into r->out. */
static bool read_ply(reader *r)
{
    if (!parse_header(r))
        return false;
    for (int e = 0; e < r->element_count; e++)
        if (!read_element(r, e))
            return false;
    if (!check_end(r))
        return false;
    if (r->out->vertex_count == 0)
        return fail(r, "the file has no vertices");
    if (r->out->triangle_count == 0)
        return fail(r, "the file has no faces");
    normalize_normals(r->out);
    return true;
}

/* ------------------------------------------------------------------ entry points */

rt_status ply_load_memory(const void *bytes, size_t size, const char *name, ply_mesh *out, rt_error *error)
{
    if (out == NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "PLY: no mesh to load into");
    memset(out, 0, sizeof *out);
    if (name == NULL)
        name = "<memory>";
    reader r = {.data = bytes, .size = bytes != NULL ? size : 0, .vertex_element = -1, .face_element = -1,
                .out = out};
    bool ok = read_ply(&r);
    for (int e = 0; e < r.element_count; e++)
        free(r.elements[e].properties);
    free(r.elements);
    if (ok)
        return RT_OK;
    ply_mesh_free(out);
    return rt_error_set(error, r.out_of_memory ? RT_ERROR_RUNTIME : RT_ERROR_INPUT, "PLY: cannot read '%s': %s",
                        name, r.reason);
}

rt_status ply_load(const char *path, ply_mesh *out, rt_error *error)
{
    if (out != NULL)
        memset(out, 0, sizeof *out);
    if (path == NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "PLY: no path to read a mesh from");
    struct stat info;
    if (stat(path, &info) != 0)
        return rt_error_set(error, RT_ERROR_INPUT, "PLY: cannot read '%s': %s", path, strerror(errno));
    if (S_ISDIR(info.st_mode))
        return rt_error_set(error, RT_ERROR_INPUT, "PLY: cannot read '%s': it is a directory", path);
    FILE *file = fopen(path, "rb");
    if (file == NULL)
        return rt_error_set(error, RT_ERROR_INPUT, "PLY: cannot read '%s': %s", path, strerror(errno));
    unsigned char *data = NULL;
    size_t size = 0, capacity = 0;
    bool memory = true;
    for (;;) {
        if (!array_reserve((void **)&data, &capacity, size + 65536, 1)) {
            memory = false;
            break;
        }
        size_t n = fread(data + size, 1, capacity - size, file);
        size += n;
        if (n == 0)
            break;
    }
    bool failed = ferror(file) != 0;
    fclose(file);
    rt_status status;
    if (!memory)
        status = rt_error_set(error, RT_ERROR_RUNTIME, "PLY: cannot read '%s': out of memory", path);
    else if (failed)
        status = rt_error_set(error, RT_ERROR_INPUT, "PLY: cannot read '%s': %s", path, strerror(EIO));
    else
        status = ply_load_memory(data, size, path, out, error);
    free(data);
    return status;
}

void ply_mesh_free(ply_mesh *mesh)
{
    if (mesh == NULL)
        return;
    free(mesh->positions);
    free(mesh->normals);
    free(mesh->uvs);
    free(mesh->colors);
    free(mesh->indices);
    memset(mesh, 0, sizeof *mesh);
}
