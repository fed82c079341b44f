/* volume_file_tetgen.c — TetGen .node/.ele reader. The first node's index decides 0- or 1-based
 * numbering, as TetGen itself does. */
#include "scene/volume_file.h"
#include "core/error.h"
#include "core/file.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    char *buf;
    char *p;
    int line;
    const char *name;
} tg_reader;

/* The whole file as a reader at its first line (r->buf is the caller's to free). The text is
 * parsed as a C string: a NUL inside would silently end it early. */
static vfx_result reader_open(const char *path, tg_reader *rd, size_t *size, char *err, size_t errlen)
{
    char *buf = NULL;
    vfx_result r = rt_read_file(path, RT_VOLUME_MAX_FILE_BYTES,
                                "1 GiB for a volume file (RT_VOLUME_MAX_FILE_BYTES)", &buf, size, err, errlen);
    const char *z = r ? NULL : memchr(buf, 0, *size);
    if (z) {
        snprintf(err, errlen, "%s: byte %zu is a NUL byte (not a text file?)", path, (size_t)(z - buf));
        free(buf);
        return VFX_ERR_FORMAT;
    }
    *rd = (tg_reader){buf, buf, 0, path};
    return r;
}

/* Header counts are whole numbers: 2.5 points is a damaged header, not 2. */
static int whole(double x) { return x == floor(x); }

/* Next non-empty, comment-stripped line into *line (NUL-terminated in place); 0 at end. */
static int next_line(tg_reader *r, char **line)
{
    while (*r->p) {
        char *s = r->p;
        char *e = strchr(s, '\n');
        if (e) {
            *e = 0;
            r->p = e + 1;
        } else {
            r->p = s + strlen(s);
        }
        r->line++;
        char *h = strchr(s, '#');
        if (h)
            *h = 0;
        while (*s == ' ' || *s == '\t' || *s == '\r')
            s++;
        if (*s) {
            *line = s;
            return 1;
        }
    }
    return 0;
}

static int parse_numbers(char *s, double *v, int maxn)
{
    int n = 0;
    while (n < maxn) {
        char *e;
        errno = 0;
        double x = strtod(s, &e);
        if (e == s)
            break;
        v[n++] = x;
        s = e;
    }
    while (*s == ' ' || *s == '\t' || *s == '\r' || *s == ',')
        s++;
    return *s ? -1 : n; /* trailing garbage is an error */
}

#define TG_MAXCOL 64

/* A header's count against its cap and the file's size. Every item takes a line of at least 2
 * bytes: a header claiming more than that is truncated, refused before allocating for the
 * claimed count (found by fuzz_tetgen: a 9-byte file asked for 12 GB). Loose on purpose: near
 * misses get the exact "i of n". */
static vfx_result header_count(const tg_reader *r, size_t sz, double n, const char *what, uint32_t cap,
                               const char *cap_name, char *err, size_t errlen)
{
    if (n > cap)
        return rt_errf(err, errlen, VFX_ERR_FORMAT, "%s: header claims %.0f %s, above the cap of %u (%s)",
                       r->name, n, what, cap, cap_name);
    if (n > (double)sz / 2)
        return rt_errf(err, errlen, VFX_ERR_FORMAT, "%s: truncated: header claims %g %s, file has %zu bytes",
                       r->name, n, what, sz);
    return VFX_OK;
}

/* .node header: "points [dimension 3] [attributes] [markers 0|1]", checked against the caps
 * and against the file's size. */
static vfx_result node_header(tg_reader *r, size_t sz, double *np, int *nattr, int *nmark,
                              char *err, size_t errlen)
{
    double v[TG_MAXCOL];
    char *line;
    int n;
    if (!next_line(r, &line) || (n = parse_numbers(line, v, TG_MAXCOL)) < 1)
        return rt_errf(err, errlen, VFX_ERR_FORMAT, "%s: missing or bad header line", r->name);
    double p = v[0], dim = n > 1 ? v[1] : 3, na = n > 2 ? v[2] : 0, nm = n > 3 ? v[3] : 0;
    if (p < 4 || p > 1e9 || dim != 3 || na < 0 || na > TG_MAXCOL - 5 || nm < 0 || nm > 1 ||
        !whole(p) || !whole(na) || !whole(nm))
        return rt_errf(err, errlen, VFX_ERR_FORMAT,
                       "%s:%d: bad header (points %g, dimension %g, attributes %g, markers %g)", r->name,
                       r->line, p, dim, na, nm);
    vfx_result res = header_count(r, sz, p, "points", RT_VOLUME_MAX_POINTS, "RT_VOLUME_MAX_POINTS",
                                  err, errlen);
    if (res)
        return res;
    *np = p, *nattr = (int)na, *nmark = (int)nm;
    return VFX_OK;
}

/* The attribute the scalar comes from: "attrK" with K < nattr ("" is attr0); -1 without a
 * scalar_name. VFX_ERR_NOT_FOUND naming what the file has otherwise. */
static vfx_result node_scalar(const char *path, const char *scalar_name, int nattr, int *attr_index,
                              char *err, size_t errlen)
{
    *attr_index = -1;
    if (!scalar_name)
        return VFX_OK;
    int k = 0;
    int named = !*scalar_name || (sscanf(scalar_name, "attr%d", &k) == 1 && k >= 0);
    if (named && k < nattr) {
        *attr_index = k;
        return VFX_OK;
    }
    if (!named || nattr > 0)
        return rt_errf(err, errlen, VFX_ERR_NOT_FOUND,
                       "%s: scalar field '%s' not found; present: attr0..attr%d",
                       path, scalar_name, nattr - 1);
    return rt_errf(err, errlen, VFX_ERR_NOT_FOUND,
                   "%s: scalar field '%s' not found; the file has no node attributes", path, scalar_name);
}

/* Item i of count (a point or a tetrahedron): the next line, exactly cols numbers into v. */
static vfx_result item_line(tg_reader *r, const char *one, const char *many, uint32_t i, uint32_t count,
                            int cols, double *v, char *err, size_t errlen)
{
    char *line;
    if (!next_line(r, &line))
        return rt_errf(err, errlen, VFX_ERR_FORMAT, "%s: truncated: %u of %u %s", r->name, i, count, many);
    int n = parse_numbers(line, v, TG_MAXCOL);
    if (n != cols)
        return rt_errf(err, errlen, VFX_ERR_FORMAT, "%s:%d: %s %u has %d numbers, expected %d", r->name,
                       r->line, one, i, n, cols);
    return VFX_OK;
}

/* One .node point line: "index x y z attributes... [marker]"; the first index sets *base. */
static vfx_result node_point(tg_reader *r, uint32_t i, int cols, int attr_index, int *base, tet_mesh *out,
                             char *err, size_t errlen)
{
    double v[TG_MAXCOL];
    vfx_result res = item_line(r, "point", "points", i, out->point_count, cols, v, err, errlen);
    if (res)
        return res;
    if (i == 0) {
        if (v[0] != 0 && v[0] != 1)
            return rt_errf(err, errlen, VFX_ERR_FORMAT, "%s:%d: first point index %g is neither 0 nor 1",
                           r->name, r->line, v[0]);
        *base = (int)v[0];
    }
    if (v[0] != (double)i + *base)
        return rt_errf(err, errlen, VFX_ERR_FORMAT, "%s:%d: point index %g, expected %u", r->name, r->line,
                       v[0], i + *base);
    /* Checked here, as float32, so the message has the file and line (1e39 is finite as a
     * double and Inf as the float the renderer uses). */
    for (int k = 0; k < 3; k++) {
        out->points[3 * (size_t)i + k] = (float)v[1 + k];
        if (!isfinite(out->points[3 * (size_t)i + k]))
            return rt_errf(err, errlen, VFX_ERR_NUMERIC,
                           "%s:%d: point %u coordinate %c = %g is not finite as float32",
                           r->name, r->line, i, "xyz"[k], v[1 + k]);
        if (fabs(v[1 + k]) > RT_VOLUME_MAX_COORD)
            return rt_errf(err, errlen, VFX_ERR_INVALID_ARGUMENT,
                           "%s:%d: point %u coordinate %c = %g is beyond +-%g (RT_VOLUME_MAX_COORD): so far a "
                           "point makes every cell degenerate next to the mesh's extent",
                           r->name, r->line, i, "xyz"[k], v[1 + k], RT_VOLUME_MAX_COORD);
    }
    if (attr_index >= 0) {
        out->scalar[i] = (float)v[4 + attr_index];
        if (!isfinite(out->scalar[i]))
            return rt_errf(err, errlen, VFX_ERR_NUMERIC,
                           "%s:%d: point %u attribute %d = %g is not finite as float32",
                           r->name, r->line, i, attr_index, v[4 + attr_index]);
    }
    return VFX_OK;
}

/* The .node file: points (and the chosen attribute as the scalar) into out; *base is the
 * numbering (0 or 1) the .ele file's indices use. */
static vfx_result read_node(const char *path, const char *scalar_name, tet_mesh *out, int *base,
                            char *err, size_t errlen)
{
    tg_reader r;
    size_t sz;
    vfx_result res = reader_open(path, &r, &sz, err, errlen);
    if (res)
        return res;
    double np = 0;
    int nattr = 0, nmark = 0, attr_index = -1;
    if ((res = node_header(&r, sz, &np, &nattr, &nmark, err, errlen))
        || (res = node_scalar(path, scalar_name, nattr, &attr_index, err, errlen)))
        goto done;
    out->point_count = (uint32_t)np;
    out->points = malloc(sizeof(float) * 3 * (size_t)np);
    if (attr_index >= 0) {
        out->scalar = malloc(sizeof(float) * (size_t)np);
        snprintf(out->scalar_name, sizeof out->scalar_name, "attr%d", attr_index);
    }
    if (!out->points || (attr_index >= 0 && !out->scalar)) {
        res = rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY,
                      "%s: out of memory for %u points", path, out->point_count);
        goto done;
    }
    *base = 0;
    for (uint32_t i = 0; i < out->point_count && !res; i++)
        res = node_point(&r, i, 4 + nattr + nmark, attr_index, base, out, err, errlen);
done:
    free(r.buf);
    return res;
}

/* .ele header: "tetrahedra [nodes per tet 4|10] [attributes]"; *cols the numbers per line. */
static vfx_result ele_header(tg_reader *r, size_t sz, double *nt, int *cols, char *err, size_t errlen)
{
    double v[TG_MAXCOL];
    char *line;
    int n;
    if (!next_line(r, &line) || (n = parse_numbers(line, v, TG_MAXCOL)) < 1)
        return rt_errf(err, errlen, VFX_ERR_FORMAT, "%s: missing or bad header line", r->name);
    double t = v[0], npt = n > 1 ? v[1] : 4, neattr = n > 2 ? v[2] : 0;
    if (t < 1 || t > 1e9 || (npt != 4 && npt != 10) || neattr < 0 || neattr > TG_MAXCOL - 12 ||
        !whole(t) || !whole(neattr))
        return rt_errf(err, errlen, VFX_ERR_FORMAT,
                       "%s:%d: bad header (tetrahedra %g, nodes per tet %g, attributes %g)",
                       r->name, r->line, t, npt, neattr);
    vfx_result res = header_count(r, sz, t, "tetrahedra", RT_VOLUME_MAX_TETS, "RT_VOLUME_MAX_TETS",
                                  err, errlen);
    if (res)
        return res;
    *nt = t;
    *cols = 1 + (int)npt + (int)neattr;
    return VFX_OK;
}

/* One .ele line: "index v0 v1 v2 v3 [6 more nodes] [attributes]"; the corners, in range of
 * the points in the given numbering, into out->tets. */
static vfx_result ele_tet(tg_reader *r, uint32_t t, int cols, int base, tet_mesh *out,
                          char *err, size_t errlen)
{
    double v[TG_MAXCOL];
    vfx_result res = item_line(r, "tetrahedron", "tetrahedra", t, out->tet_count, cols, v, err, errlen);
    if (res)
        return res;
    for (int k = 0; k < 4; k++) {
        double idx = v[1 + k] - base;
        if (!(idx >= 0 && idx < (double)out->point_count) || idx != (double)(uint32_t)idx)
            return rt_errf(err, errlen, VFX_ERR_FORMAT,
                           "%s:%d: tetrahedron %u vertex %d index %g out of range "
                           "(%u points, %d-based)", r->name, r->line, t, k, v[1 + k], out->point_count, base);
        out->tets[4 * (size_t)t + k] = (uint32_t)idx;
    }
    return VFX_OK;
}

/* The .ele file: the tetrahedra over out's points, numbered from base. */
static vfx_result read_ele(const char *path, int base, tet_mesh *out, char *err, size_t errlen)
{
    tg_reader r;
    size_t sz;
    vfx_result res = reader_open(path, &r, &sz, err, errlen);
    if (res)
        return res;
    double nt = 0;
    int cols = 0;
    if ((res = ele_header(&r, sz, &nt, &cols, err, errlen)))
        goto done;
    out->tet_count = (uint32_t)nt;
    out->tets = malloc(sizeof(uint32_t) * 4 * (size_t)nt);
    if (!out->tets) {
        res = rt_errf(err, errlen, VFX_ERR_OUT_OF_MEMORY,
                      "%s: out of memory for %u tetrahedra", path, out->tet_count);
        goto done;
    }
    for (uint32_t t = 0; t < out->tet_count && !res; t++)
        res = ele_tet(&r, t, cols, base, out, err, errlen);
done:
    free(r.buf);
    return res;
}

vfx_result rt_volume_load_tetgen(const char *path_base, const char *scalar_name,
                               tet_mesh *out, char *err, size_t errlen)
{
    if (!path_base || !out) {
        snprintf(err, errlen, "NULL argument");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    memset(out, 0, sizeof *out);
    size_t plen = strlen(path_base);
    char *path = malloc(plen + 8);
    if (!path) {
        snprintf(err, errlen, "%s: out of memory for the path", path_base);
        return VFX_ERR_OUT_OF_MEMORY;
    }
    int base = 0;
    snprintf(path, plen + 8, "%s.node", path_base);
    vfx_result res = read_node(path, scalar_name, out, &base, err, errlen);
    if (!res) {
        snprintf(path, plen + 8, "%s.ele", path_base);
        res = read_ele(path, base, out, err, errlen);
    }
    if (!res) {
        char inner[256] = "";
        res = rt_result_from_tet(tet_validate(out, inner, sizeof inner));
        if (res)
            snprintf(err, errlen, "%s.node/.ele: %s", path_base, inner);
    }
    if (res != VFX_OK)
        tet_mesh_free(out);
    free(path);
    return res;
}
