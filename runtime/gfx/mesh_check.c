/* mesh_check.c — see mesh_check.h. */
#include "gfx/mesh_check.h"

#include <cjson/cJSON.h>

#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static const struct {
    const char *ext;
    rt_mesh_format fmt;
} formats[] = {
    {"obj", RT_MESH_FORMAT_OBJ}, {"ply", RT_MESH_FORMAT_PLY}, {"stl", RT_MESH_FORMAT_STL},
    {"gltf", RT_MESH_FORMAT_GLTF}, {"glb", RT_MESH_FORMAT_GLB},
};

rt_mesh_format rt_mesh_format_of_name(const char *name)
{
    const char *dot = name ? strrchr(name, '.') : NULL;
    if (!dot || strchr(dot, '/'))
        return RT_MESH_FORMAT_NONE;
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; ++i)
        if (strcasecmp(dot + 1, formats[i].ext) == 0)
            return formats[i].fmt;
    return RT_MESH_FORMAT_NONE;
}

const char *rt_mesh_format_ext(rt_mesh_format f)
{
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; ++i)
        if (formats[i].fmt == f)
            return formats[i].ext;
    return NULL;
}

static vfx_result check_gltf_nodes(const cJSON *root, const char *name, char *err, size_t errlen);

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* ---- PLY ---------------------------------------------------------------------------------- */

/* Bytes of a PLY scalar type in a binary body, 0 if the name is no type. */
static unsigned ply_type_size(const char *t)
{
    static const struct {
        const char *name;
        unsigned size;
    } types[] = {
        {"char", 1},  {"uchar", 1},  {"int8", 1},   {"uint8", 1},   {"short", 2},   {"ushort", 2},
        {"int16", 2}, {"uint16", 2}, {"int", 4},    {"uint", 4},    {"int32", 4},   {"uint32", 4},
        {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8},
    };
    for (size_t i = 0; i < sizeof types / sizeof types[0]; ++i)
        if (strcmp(t, types[i].name) == 0)
            return types[i].size;
    return 0;
}

#define PLY_MAX_PROPS 32

typedef struct ply_element {
    char name[32];
    unsigned long long count;
    unsigned props;          /* properties (a list counts once) */
    unsigned long long bytes; /* binary: the least bytes one instance takes */
    unsigned line;
    unsigned char size[PLY_MAX_PROPS];     /* a scalar's bytes, or a list item's */
    unsigned char list[PLY_MAX_PROPS];     /* a list's count bytes; 0 for a scalar */
    unsigned char signed_count[PLY_MAX_PROPS];
} ply_element;

/* Next header line [*pos, end) into `line` (NUL-terminated, CR dropped); 0 at the end of data. */
static int ply_line(const unsigned char *d, size_t size, size_t *pos, char *line, size_t cap,
                    int *too_long, int *bad_byte)
{
    if (*pos >= size)
        return 0;
    size_t n = 0;
    *too_long = 0;
    *bad_byte = 0;
    while (*pos < size && d[*pos] != '\n') {
        unsigned char c = d[*pos];
        /* the header is ASCII text; a CR only ends a line (Assimp 5.2 looped forever on a
         * lone CR followed by bytes above 127, found by fuzz_mesh_ply) */
        if ((c < 0x20 && c != '\t' && !(c == '\r' && *pos + 1 < size && d[*pos + 1] == '\n')) || c > 0x7e)
            *bad_byte = 1;
        if (n + 1 < cap)
            line[n++] = (char)d[*pos];
        else
            *too_long = 1;
        ++*pos;
    }
    if (*pos < size)
        ++*pos; /* the '\n' */
    while (n > 0 && isspace((unsigned char)line[n - 1])) /* CR, trailing blanks */
        --n;
    line[n] = 0;
    return 1;
}

#define PLY_MAX_ELEMENTS 16

static vfx_result ply_fail(const char *name, char *err, size_t errlen, const char *fmt, unsigned line,
                           const char *what)
{
    char msg[192];
    snprintf(msg, sizeof msg, fmt, what);
    snprintf(err, errlen, "%s: PLY header line %u: %s", name, line, msg);
    return VFX_ERR_FORMAT;
}

/* Walks the body, instance by instance: every list's count (in the body, where no header check
 * sees it) must fit in what follows. Assimp sizes a list by its count before reading it (an
 * ASCII face claiming 4e9 indices asked for 32 GB). Binary: bytes; ASCII: one line an instance,
 * as Assimp reads it, holding every value and every list item. */
static vfx_result ply_walk_body(const unsigned char *d, size_t size, size_t pos, int binary,
                                const ply_element *el, unsigned nel, const char *name, char *err,
                                size_t errlen)
{
    for (unsigned i = 0; i < nel; ++i) {
        const ply_element *e = &el[i];
        for (unsigned long long k = 0; k < e->count; ++k) {
            size_t eol = pos;
            if (!binary) {
                while (pos < size && isspace(d[pos])) /* blank lines between instances */
                    ++pos;
                eol = pos;
                while (eol < size && d[eol] != '\n')
                    ++eol;
            }
            for (unsigned p = 0; p < e->props; ++p) {
                unsigned long long n = 1; /* items this property holds */
                size_t item = e->size[p];
                if (binary && e->list[p]) {
                    unsigned cs = e->list[p];
                    if (size - pos < cs)
                        goto truncated;
                    unsigned long long v = 0;
                    for (unsigned b = 0; b < cs; ++b)
                        v |= (unsigned long long)d[pos + (binary == 2 ? cs - 1 - b : b)] << (8 * b);
                    if (e->signed_count[p] && (v >> (8 * cs - 1)) & 1)
                        goto negative;
                    pos += cs;
                    n = v;
                } else if (!binary && e->list[p]) {
                    while (pos < eol && (d[pos] == ' ' || d[pos] == '\t' || d[pos] == '\r'))
                        ++pos;
                    if (pos == eol)
                        goto truncated;
                    if (d[pos] == '-')
                        goto negative;
                    unsigned long long v = 0;
                    for (; pos < eol && isdigit(d[pos]); ++pos)
                        v = v > 1ull << 40 ? v : v * 10 + (d[pos] - '0');
                    n = v;
                }
                if (binary) {
                    if (n > (size - pos) / item)
                        goto too_many;
                    pos += n * item;
                    continue;
                }
                for (unsigned long long t = 0; t < n; ++t) { /* n tokens on this line */
                    while (pos < eol && (d[pos] == ' ' || d[pos] == '\t' || d[pos] == '\r'))
                        ++pos;
                    if (pos == eol) {
                        if (e->list[p])
                            goto too_many;
                        goto truncated;
                    }
                    while (pos < eol && !(d[pos] == ' ' || d[pos] == '\t' || d[pos] == '\r'))
                        ++pos;
                }
                continue;
            too_many:
                snprintf(err, errlen, "%s: PLY body: element %s %llu, property %u: a list of %llu items, more "
                         "than the %s holds (truncated or lying)", name, e->name, k, p, n, binary ? "file" : "line");
                return VFX_ERR_FORMAT;
            negative:
                snprintf(err, errlen, "%s: PLY body: element %s %llu, property %u: a negative list count", name,
                         e->name, k, p);
                return VFX_ERR_FORMAT;
            truncated:
                snprintf(err, errlen, "%s: PLY body: element %s %llu of %llu, property %u: the %s ends (truncated)",
                         name, e->name, k, e->count, p, binary ? "file" : "line");
                return VFX_ERR_FORMAT;
            }
            if (!binary)
                pos = eol;
        }
    }
    return VFX_OK;
}

/* Element names Assimp 5.2 knows (PLY::Element::ParseSemantic). It reads the count of any other
 * from the start of its name (the name is not skipped first): 0 for a name that starts with a
 * letter, so it reads none of its instances (TextureFile takes no count at all). */
static int ply_assimp_parses(const char *name)
{
    static const char *const known[] = {"vertex", "face", "tristrips", "edge", "material"};
    for (size_t i = 0; i < sizeof known / sizeof known[0]; ++i)
        if (strcmp(name, known[i]) == 0)
            return 1;
    return 0;
}

/* An ASCII body is text: printable ASCII, blanks, tabs, and lines ended by LF or CR LF. A lone
 * CR, a NUL or a form feed is where readers disagree on line ends (Assimp 5.2 ends a line at
 * each, so its face line was not this walk's one: a count of 4e9 read from another line). */
static vfx_result ply_ascii_text(const unsigned char *d, size_t size, size_t pos, const char *name, char *err,
                                 size_t errlen)
{
    for (unsigned long long line = 1; pos < size; ++pos) {
        unsigned char ch = d[pos];
        if (ch == '\n')
            ++line;
        else if ((ch < 0x20 && ch != '\t' && !(ch == '\r' && pos + 1 < size && d[pos + 1] == '\n')) || ch > 0x7e) {
            snprintf(err, errlen, "%s: PLY body line %llu: byte 0x%02x is not ASCII text (a lone CR, NUL or form "
                     "feed makes readers disagree on where lines end)", name, line, ch);
            return VFX_ERR_FORMAT;
        }
    }
    return VFX_OK;
}

/* One "property" line of the header (its words w[0..nw-1], line ln) into element e (NULL before
 * any element): its size, or a list's count and item sizes; props_end is the line that ended
 * the element's properties for Assimp (0 while none has). */
static vfx_result ply_property(ply_element *e, char w[5][64], int nw, unsigned ln, unsigned props_end,
                               const char *name, char *err, size_t errlen)
{
    if (!e)
        return ply_fail(name, err, errlen, "%s", ln, "a property before any element");
    if (props_end) {
        char why[96];
        snprintf(why, sizeof why, "a property after line %u, which is not one (Assimp 5.2 ends the", props_end);
        return ply_fail(name, err, errlen, "%s element's properties there and would drop this one; move "
                        "that line above the element)", ln, why);
    }
    unsigned sz;
    if (e->props == PLY_MAX_PROPS)
        return ply_fail(name, err, errlen, "more than %s properties in one element", ln, "32");
    if (strcmp(w[1], "list") == 0) {
        /* a list takes at least its count: it may hold no item */
        unsigned isz = ply_type_size(w[3]);
        if (nw != 5 || !(sz = ply_type_size(w[2])) || !isz)
            return ply_fail(name, err, errlen, "%s", ln, "a list property needs two types and a name");
        if (strstr(w[2], "float") || strcmp(w[2], "double") == 0)
            return ply_fail(name, err, errlen, "a list count of type %s", ln, w[2]);
        e->list[e->props] = (unsigned char)sz;
        e->signed_count[e->props] = w[2][0] != 'u';
        e->size[e->props] = (unsigned char)isz;
    } else if (nw != 3 || !(sz = ply_type_size(w[1]))) {
        return ply_fail(name, err, errlen, "unknown property type \"%s\"", ln, w[1]);
    } else {
        e->size[e->props] = (unsigned char)sz;
    }
    e->props++;
    e->bytes += sz;
    return VFX_OK;
}

/* The header's element counts against the caps, the properties they need and the body's
 * `body` bytes (binary: fixed sizes; ASCII: a character and a separator a value). */
static vfx_result ply_counts(const ply_element *el, unsigned nel, int binary, size_t body, const char *name,
                             char *err, size_t errlen)
{
    /* the least body the header's counts need: binary adds up fixed sizes; ASCII needs one
     * character and one separator a value (the last separator may be missing) */
    unsigned long long need = 0;
    for (unsigned i = 0; i < nel; ++i) {
        const ply_element *e = &el[i];
        if (e->count > 4ull * RT_MESH_MAX_IMPORT_VERTICES
            || (strcmp(e->name, "vertex") == 0 && e->count > RT_MESH_MAX_IMPORT_VERTICES)) {
            snprintf(err, errlen, "%s: PLY header line %u: element %s claims %llu, above the cap of %u", name,
                     e->line, e->name, e->count,
                     strcmp(e->name, "vertex") == 0 ? RT_MESH_MAX_IMPORT_VERTICES : 4u * RT_MESH_MAX_IMPORT_VERTICES);
            return VFX_ERR_FORMAT;
        }
        if (e->count > 0 && e->props == 0) {
            snprintf(err, errlen, "%s: PLY header line %u: element %s claims %llu but has no property",
                     name, e->line, e->name, e->count);
            return VFX_ERR_FORMAT;
        }
        /* an element Assimp does not know is empty to it, so the data of the next one it knows
         * would be read from this one's bytes (a uint list count of 4e9 from a float: 32 GB asked,
         * found by fuzz_mesh_ply in CI) */
        for (unsigned j = i + 1; e->count > 0 && !ply_assimp_parses(e->name) && j < nel; ++j)
            if (ply_assimp_parses(el[j].name)) {
                snprintf(err, errlen, "%s: PLY header line %u: element %s (%llu) comes before element %s, and "
                         "Assimp 5.2 reads an element it does not know as empty: it would read %s from %s's "
                         "data; put %s after the mesh's elements or leave it out", name, e->line, e->name,
                         e->count, el[j].name, el[j].name, e->name, e->name);
                return VFX_ERR_FORMAT;
            }
        need += e->count * (binary ? e->bytes : 2ull * e->props); /* <= 2^24 * 16 * 8 * ...: no overflow */
        if (need > body + (binary ? 0 : 1)) {
            snprintf(err, errlen,
                     "%s: PLY header line %u: element %s claims %llu, which needs at least %llu bytes "
                     "of %s data; the file holds %zu after the header (truncated or lying)",
                     name, e->line, e->name, e->count, need - (binary ? 0 : 1), binary ? "binary" : "ASCII", body);
            return VFX_ERR_FORMAT;
        }
    }
    return VFX_OK;
}

static vfx_result check_ply(const unsigned char *d, size_t size, const char *name, char *err,
                            size_t errlen)
{
    size_t pos = 0;
    char line[256];
    int too_long = 0, bad_byte = 0;
    unsigned ln = 0;
    int binary = -1;
    ply_element el[PLY_MAX_ELEMENTS];
    unsigned nel = 0;
    int ended = 0;
    unsigned props_end = 0; /* the line that ended the current element's properties for Assimp */
    while (!ended && ply_line(d, size, &pos, line, sizeof line, &too_long, &bad_byte)) {
        ++ln;
        if (too_long)
            return ply_fail(name, err, errlen, "longer than %s characters", ln, "255");
        if (bad_byte)
            return ply_fail(name, err, errlen, "%s", ln, "a byte that is not ASCII text (or a CR not ending the line)");
        char w[5][64] = {{0}};
        int nw = sscanf(line, "%63s %63s %63s %63s %63s", w[0], w[1], w[2], w[3], w[4]);
        if (ln == 1) {
            if (strcmp(line, "ply") != 0)
                return ply_fail(name, err, errlen, "%s", ln, "not a PLY file (no \"ply\" on the first line)");
            continue;
        }
        /* Assimp 5.2 ends an element's properties at the first line that is not one (a comment,
         * a blank line, anything): it drops the properties after it and reads the body with fewer
         * (an ASCII vertex lost y and z; a binary body shifts) */
        if (nel > 0 && !props_end && (nw <= 0 || strcmp(w[0], "property") != 0))
            props_end = ln;
        if (nw <= 0 || strcmp(w[0], "comment") == 0 || strcmp(w[0], "obj_info") == 0)
            continue;
        if (strcmp(w[0], "format") == 0) {
            if (nw < 2 || binary >= 0)
                return ply_fail(name, err, errlen, "%s", ln, "a second or empty format line");
            if (strcmp(w[1], "ascii") == 0)
                binary = 0;
            else if (strcmp(w[1], "binary_little_endian") == 0)
                binary = 1;
            else if (strcmp(w[1], "binary_big_endian") == 0)
                binary = 2;
            else
                return ply_fail(name, err, errlen, "unknown format \"%s\"", ln, w[1]);
        } else if (strcmp(w[0], "element") == 0) {
            char *end = NULL;
            unsigned long long c = nw == 3 && isdigit((unsigned char)w[2][0]) ? strtoull(w[2], &end, 10) : 0;
            if (nw != 3 || !end || *end)
                return ply_fail(name, err, errlen, "%s", ln, "an element line needs a name and a count");
            /* Assimp 5.2 reads an element's count from the start of a name it does not know, so a
             * name of digits became a count of billions (fuzz_mesh_ply: 2.9 GB in one vector) */
            if (!isalpha((unsigned char)w[1][0]) && w[1][0] != '_')
                return ply_fail(name, err, errlen, "element name \"%s\" does not start with a letter", ln, w[1]);
            if (nel == PLY_MAX_ELEMENTS)
                return ply_fail(name, err, errlen, "more than %s elements", ln, "16");
            for (unsigned k = 0; k < nel; ++k)
                if (strcmp(el[k].name, w[1]) == 0) /* Assimp 5.2 corrupts its heap on a repeat */
                    return ply_fail(name, err, errlen, "element %s declared twice", ln, w[1]);
            ply_element *e = &el[nel++];
            memset(e, 0, sizeof *e);
            snprintf(e->name, sizeof e->name, "%.31s", w[1]);
            e->count = c;
            e->line = ln;
            props_end = 0;
        } else if (strcmp(w[0], "property") == 0) {
            vfx_result r = ply_property(nel ? &el[nel - 1] : NULL, w, nw, ln, props_end, name, err, errlen);
            if (r)
                return r;
        } else if (strcmp(w[0], "end_header") == 0) {
            ended = 1;
        } /* other lines are skipped, as Assimp does (Blender wrote "Created by ..." there) */
    }
    if (ended && d[pos - 1] != '\n') {
        /* Assimp 5.2's header loop never ends when end_header is the file's last bytes: its
         * line reader fails there, keeps the line unterminated, and is asked again forever
         * (fuzz_mesh_ply timeout) */
        snprintf(err, errlen, "%s: PLY header line %u: end_header ends the file with no line end after it", name, ln);
        return VFX_ERR_FORMAT;
    }
    if (ended && nel == 0) {
        snprintf(err, errlen, "%s: PLY header declares no element", name);
        return VFX_ERR_FORMAT;
    }
    if (!ended || binary < 0) {
        snprintf(err, errlen, "%s: PLY header %s", name, !ended ? "has no end_header (truncated?)" : "has no format line");
        return VFX_ERR_FORMAT;
    }
    vfx_result r = ply_counts(el, nel, binary, size - pos, name, err, errlen);
    if (r)
        return r;
    r = binary ? VFX_OK : ply_ascii_text(d, size, pos, name, err, errlen);
    return r ? r : ply_walk_body(d, size, pos, binary, el, nel, name, err, errlen);
}

/* ---- STL ---------------------------------------------------------------------------------- */

static vfx_result check_stl(const unsigned char *d, size_t size, const char *name, char *err,
                            size_t errlen)
{
    if (size >= 84) {
        unsigned long long n = le32(d + 80), need = 84ull + 50ull * n;
        if (need == size) {
            if (3ull * n > RT_MESH_MAX_IMPORT_VERTICES) {
                snprintf(err, errlen, "%s: binary STL of %llu triangles: %llu vertices, above the cap of %u",
                         name, n, 3ull * n, RT_MESH_MAX_IMPORT_VERTICES);
                return VFX_ERR_FORMAT;
            }
            return VFX_OK;
        }
        /* Assimp computes 84 + 50 N in 32 bits: a count that wraps to the size would pass it */
        if ((uint32_t)need == size) {
            snprintf(err, errlen, "%s: binary STL claims %llu triangles (%llu bytes); the file has %zu", name,
                     n, need, size);
            return VFX_ERR_FORMAT;
        }
    }
    size_t i = 0;
    while (i < size && i < 256 && isspace(d[i]))
        ++i;
    if (size - i >= 5 && memcmp(d + i, "solid", 5) == 0)
        return VFX_OK; /* ASCII: Assimp's parse holds what the text says, bounded by its size */
    if (size >= 84)
        snprintf(err, errlen,
                 "%s: not an STL file: binary STL needs 84 + 50 x N bytes (the header claims N = %u: %llu), "
                 "the file has %zu, and it does not start with \"solid\" (ASCII)",
                 name, le32(d + 80), 84ull + 50ull * le32(d + 80), size);
    else
        snprintf(err, errlen, "%s: not an STL file: %zu bytes, under a binary STL's 84, and no \"solid\" (ASCII)",
                 name, size);
    return VFX_ERR_FORMAT;
}

/* ---- glb ---------------------------------------------------------------------------------- */

static vfx_result check_glb(const unsigned char *d, size_t size, const char *name, char *err,
                            size_t errlen)
{
    if (size < 20 || memcmp(d, "glTF", 4) != 0) {
        snprintf(err, errlen, "%s: not a glb file (%s)", name, size < 20 ? "under 20 bytes" : "no \"glTF\" magic");
        return VFX_ERR_FORMAT;
    }
    uint32_t version = le32(d + 4), length = le32(d + 8);
    if (version != 2) {
        snprintf(err, errlen, "%s: glb version %u; only glTF 2.0 binary is imported", name, version);
        return VFX_ERR_FORMAT;
    }
    if (length != size) {
        snprintf(err, errlen, "%s: glb header claims %u bytes; the file has %zu (truncated or lying)", name,
                 length, size);
        return VFX_ERR_FORMAT;
    }
    size_t off = 12;
    for (unsigned k = 0; off < size; ++k) {
        if (size - off < 8) {
            snprintf(err, errlen, "%s: glb chunk %u at byte %zu: %zu bytes left, under a chunk header's 8", name,
                     k, off, size - off);
            return VFX_ERR_FORMAT;
        }
        uint32_t clen = le32(d + off), ctype = le32(d + off + 4);
        if (clen > size - off - 8) {
            snprintf(err, errlen, "%s: glb chunk %u at byte %zu claims %u bytes; %zu follow (truncated or lying)",
                     name, k, off, clen, size - off - 8);
            return VFX_ERR_FORMAT;
        }
        if (k == 0 && ctype != 0x4E4F534Au) { /* "JSON" */
            snprintf(err, errlen, "%s: glb chunk 0 is not JSON (type 0x%08x)", name, ctype);
            return VFX_ERR_FORMAT;
        }
        if (k == 0) { /* the node tree, before Assimp builds it */
            cJSON *root = cJSON_ParseWithLength((const char *)d + off + 8, clen);
            vfx_result r = root ? check_gltf_nodes(root, name, err, errlen) : VFX_OK; /* Assimp names bad JSON */
            cJSON_Delete(root);
            if (r)
                return r;
        }
        off += 8 + (size_t)clen;
    }
    return VFX_OK;
}

/* ---- OBJ ---------------------------------------------------------------------------------- */

/* OBJ has no header: count what Assimp will hold. It makes a vertex of every face corner
 * ("f 1 1 1" is 8 bytes and 3 vertices, ~230 bytes of Assimp's memory), so the corners are
 * capped before it reads the file. */
static vfx_result check_obj(const unsigned char *d, size_t size, const char *name, char *err,
                            size_t errlen)
{
    unsigned long long corners = 0, positions = 0, line = 1, first_over = 0;
    for (size_t i = 0; i < size;) {
        size_t j = i;
        while (j < size && (d[j] == ' ' || d[j] == '\t'))
            ++j;
        int face = j + 1 < size && (d[j] == 'f' || d[j] == 'l' || d[j] == 'p') && (d[j + 1] == ' ' || d[j + 1] == '\t');
        if (j + 1 < size && d[j] == 'v' && (d[j + 1] == ' ' || d[j + 1] == '\t'))
            ++positions;
        if (face)
            j += 2;
        for (int in_token = 0; j < size && d[j] != '\n'; ++j) {
            int blank = d[j] == ' ' || d[j] == '\t' || d[j] == '\r';
            if (face && !blank && !in_token)
                ++corners;
            in_token = !blank;
        }
        if (!first_over && (corners > RT_MESH_MAX_IMPORT_VERTICES || positions > RT_MESH_MAX_IMPORT_VERTICES))
            first_over = line;
        i = j + 1;
        ++line;
    }
    if (first_over) {
        snprintf(err, errlen, "%s: OBJ holds %llu vertex positions and %llu face corners; above the cap of %u "
                 "(passed at line %llu)", name, positions, corners, RT_MESH_MAX_IMPORT_VERTICES, first_over);
        return VFX_ERR_FORMAT;
    }
    return VFX_OK;
}

/* ---- glTF node trees ---------------------------------------------------------------------- */

/* A JSON number that is an integer in [0, n), or -1. */
static long gltf_index(const cJSON *v, long n)
{
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= 0) || v->valuedouble >= (double)n
        || v->valuedouble != (double)(long)v->valuedouble)
        return -1;
    return (long)v->valuedouble;
}

/* The vertices mesh `m` holds: its primitives' POSITION accessor counts (0 where unreadable:
 * Assimp checks the accessors themselves). */
static unsigned long long gltf_mesh_vertices(const cJSON *root, const cJSON *mesh)
{
    const cJSON *acc = cJSON_GetObjectItemCaseSensitive(root, "accessors");
    const cJSON *prims = cJSON_GetObjectItemCaseSensitive(mesh, "primitives");
    unsigned long long n = 0;
    const cJSON *p;
    cJSON_ArrayForEach(p, prims) {
        const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(p, "attributes");
        long a = gltf_index(cJSON_GetObjectItemCaseSensitive(attrs, "POSITION"), cJSON_GetArraySize(acc));
        const cJSON *count = a >= 0 ? cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(acc, (int)a), "count") : NULL;
        if (cJSON_IsNumber(count) && count->valuedouble > 0)
            n += count->valuedouble < 1e12 ? (unsigned long long)count->valuedouble : 1000000000000ull;
    }
    return n;
}

/* The node tree, walked without recursion: node count, one parent a node, depth, and the
 * vertices every node's mesh places. */
static vfx_result check_gltf_nodes(const cJSON *root, const char *name, char *err, size_t errlen)
{
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    const cJSON *meshes = cJSON_GetObjectItemCaseSensitive(root, "meshes");
    int n = cJSON_GetArraySize(nodes);
    if (n <= 0)
        return VFX_OK;
    if ((unsigned)n > RT_MESH_MAX_NODES) {
        snprintf(err, errlen, "%s: glTF: %d nodes, above the cap of %u", name, n, RT_MESH_MAX_NODES);
        return VFX_ERR_FORMAT;
    }
    long *parent = malloc((size_t)n * sizeof *parent);
    if (!parent) {
        snprintf(err, errlen, "%s: out of memory checking %d glTF nodes", name, n);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    for (int i = 0; i < n; ++i)
        parent[i] = -1;
    vfx_result r = VFX_OK;
    unsigned long long placed = 0;
    int i = 0;
    const cJSON *node;
    cJSON_ArrayForEach(node, nodes) {
        const cJSON *c;
        cJSON_ArrayForEach(c, cJSON_GetObjectItemCaseSensitive(node, "children")) {
            long k = gltf_index(c, n);
            if (k < 0 || k == i || parent[k] >= 0) {
                if (k < 0)
                    snprintf(err, errlen, "%s: glTF node %d: a child that is not a node index", name, i);
                else
                    snprintf(err, errlen, "%s: glTF node %ld is a child of node %ld and of node %d: nodes must form "
                             "a tree (a node with two parents is placed twice, and twice again below)", name, k,
                             k == i ? (long)i : parent[k], i);
                r = VFX_ERR_FORMAT;
                goto done;
            }
            parent[k] = i;
        }
        long m = gltf_index(cJSON_GetObjectItemCaseSensitive(node, "mesh"), cJSON_GetArraySize(meshes));
        if (m >= 0)
            placed += gltf_mesh_vertices(root, cJSON_GetArrayItem(meshes, (int)m));
        ++i;
    }
    for (i = 0; i < n; ++i) { /* a cycle never reaches a root: it is too deep too */
        unsigned depth = 0;
        for (long k = i; parent[k] >= 0 && depth <= RT_MESH_MAX_NODE_DEPTH; k = parent[k])
            ++depth;
        if (depth > RT_MESH_MAX_NODE_DEPTH) {
            snprintf(err, errlen, "%s: glTF node %d lies deeper than %u nodes below a root (or in a cycle); the "
                     "node tree may be at most %u deep", name, i, RT_MESH_MAX_NODE_DEPTH, RT_MESH_MAX_NODE_DEPTH);
            r = VFX_ERR_FORMAT;
            goto done;
        }
    }
    if (placed > RT_MESH_MAX_PLACED_VERTICES) {
        snprintf(err, errlen, "%s: glTF: %llu vertices once every node's mesh is placed (%d nodes), above the cap of "
                 "%u", name, placed, n, RT_MESH_MAX_PLACED_VERTICES);
        r = VFX_ERR_FORMAT;
    }
done:
    free(parent);
    return r;
}

/* ---- glTF JSON ---------------------------------------------------------------------------- */

/* glTF 2.0 only, as for .glb: Assimp's glTF 1.0 reader is one more format the game does not
 * need. cJSON's parse of at most the 32 MiB cap is bounded by the text. */
static vfx_result check_gltf(const unsigned char *d, size_t size, const char *name, char *err,
                             size_t errlen)
{
    cJSON *root = cJSON_ParseWithLength((const char *)d, size);
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(root, "asset"), "version");
    int ok = cJSON_IsString(v) && v->valuestring[0] == '2' && v->valuestring[1] == '.';
    vfx_result r = ok ? check_gltf_nodes(root, name, err, errlen) : VFX_ERR_FORMAT;
    if (!ok)
        snprintf(err, errlen, "%s: %s", name,
                 !root ? "not JSON (a .gltf is glTF 2.0 JSON)"
                 : !cJSON_IsString(v) ? "no asset.version string (a .gltf is glTF 2.0 JSON)"
                 : "asset.version is not 2.x; only glTF 2.0 is imported");
    cJSON_Delete(root);
    return r;
}

vfx_result rt_mesh_check_bytes(rt_mesh_format f, const unsigned char *data, size_t size,
                               const char *name, char *err, size_t errlen)
{
    if (!rt_mesh_format_ext(f)) {
        const char *dot = strrchr(name, '.');
        if (dot && !strchr(dot, '/'))
            snprintf(err, errlen, "%s: %s is not a mesh format the game imports (.obj, .ply, .stl, .gltf, .glb)",
                     name, dot);
        else
            snprintf(err, errlen, "%s: no file extension; the game imports .obj, .ply, .stl, .gltf, .glb", name);
        return VFX_ERR_FORMAT;
    }
    if (!data || size == 0) {
        snprintf(err, errlen, "%s: empty file", name);
        return VFX_ERR_FORMAT;
    }
    switch (f) {
    case RT_MESH_FORMAT_PLY: return check_ply(data, size, name, err, errlen);
    case RT_MESH_FORMAT_STL: return check_stl(data, size, name, err, errlen);
    case RT_MESH_FORMAT_GLB: return check_glb(data, size, name, err, errlen);
    case RT_MESH_FORMAT_OBJ: return check_obj(data, size, name, err, errlen);
    default: /* glTF JSON: the version here; Assimp checks every accessor and buffer against
              * the data it has, and the vertex cap applies after its raw read */
        return check_gltf(data, size, name, err, errlen);
    }
}
