/* volume_file_tetgen.c — TetGen .node/.ele reader. The first node's index decides 0- or 1-based
 * numbering, as TetGen itself does. */
#include "scene/volume_file.h"
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

/* The text is parsed as a C string: a NUL inside would silently end it early. */
static vfx_result read_whole(const char *path, char **buf, size_t *size, char *err, size_t errlen)
{
    vfx_result r = rt_read_file(path, RT_VOLUME_MAX_FILE_BYTES,
                                "1 GiB for a volume file (RT_VOLUME_MAX_FILE_BYTES)", buf, size, err, errlen);
    const char *z = r ? NULL : memchr(*buf, 0, *size);
    if (z) {
        snprintf(err, errlen, "%s: byte %zu is a NUL byte (not a text file?)", path, (size_t)(z - *buf));
        free(*buf);
        *buf = NULL;
        return VFX_ERR_FORMAT;
    }
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
    vfx_result res = VFX_OK;
    char *nodebuf = NULL, *elebuf = NULL;
    double v[TG_MAXCOL];
    size_t sz;
    char *line;

    snprintf(path, plen + 8, "%s.node", path_base);
    if ((res = read_whole(path, &nodebuf, &sz, err, errlen)))
        goto done;
    tg_reader r = {nodebuf, nodebuf, 0, path};
    int n;
    if (!next_line(&r, &line) || (n = parse_numbers(line, v, TG_MAXCOL)) < 1) {
        snprintf(err, errlen, "%s: missing or bad header line", path);
        res = VFX_ERR_FORMAT;
        goto done;
    }
    double np = v[0], dim = n > 1 ? v[1] : 3, nattr = n > 2 ? v[2] : 0, nmark = n > 3 ? v[3] : 0;
    if (np < 4 || np > 1e9 || dim != 3 || nattr < 0 || nattr > TG_MAXCOL - 5 || nmark < 0 ||
        nmark > 1 || !whole(np) || !whole(nattr) || !whole(nmark)) {
        snprintf(err, errlen,
                 "%s:%d: bad header (points %g, dimension %g, attributes %g, markers %g)", path,
                 r.line, np, dim, nattr, nmark);
        res = VFX_ERR_FORMAT;
        goto done;
    }
    if (np > RT_VOLUME_MAX_POINTS) {
        snprintf(err, errlen, "%s: header claims %.0f points, above the cap of %u "
                 "(RT_VOLUME_MAX_POINTS)", path, np, RT_VOLUME_MAX_POINTS);
        res = VFX_ERR_FORMAT;
        goto done;
    }
    /* Every point takes a line of at least 2 bytes: a header claiming more points than that is
     * truncated, refused before allocating for the claimed count (found by fuzz_tetgen: a
     * 9-byte file asked for 12 GB). Loose on purpose: near misses get the exact "i of n". */
    if (np > (double)sz / 2) {
        snprintf(err, errlen, "%s: truncated: header claims %g points, file has %zu bytes", path,
                 np, sz);
        res = VFX_ERR_FORMAT;
        goto done;
    }
    int attr_index = -1;
    if (scalar_name) {
        int k = 0;
        if (*scalar_name && (sscanf(scalar_name, "attr%d", &k) != 1 || k < 0)) {
            snprintf(err, errlen, "%s: scalar field '%s' not found; present: attr0..attr%d",
                     path, scalar_name, (int)nattr - 1);
            res = VFX_ERR_NOT_FOUND;
            goto done;
        }
        if (k >= (int)nattr) {
            if (nattr > 0)
                snprintf(err, errlen, "%s: scalar field '%s' not found; present: attr0..attr%d",
                         path, scalar_name, (int)nattr - 1);
            else
                snprintf(err, errlen, "%s: scalar field '%s' not found; the file has no node "
                         "attributes", path, scalar_name);
            res = VFX_ERR_NOT_FOUND;
            goto done;
        }
        attr_index = k;
    }
    out->point_count = (uint32_t)np;
    out->points = malloc(sizeof(float) * 3 * (size_t)np);
    if (attr_index >= 0) {
        out->scalar = malloc(sizeof(float) * (size_t)np);
        snprintf(out->scalar_name, sizeof out->scalar_name, "attr%d", attr_index);
    }
    if (!out->points || (attr_index >= 0 && !out->scalar)) {
        snprintf(err, errlen, "%s: out of memory for %u points", path, out->point_count);
        res = VFX_ERR_OUT_OF_MEMORY;
        goto done;
    }
    int base = 0;
    int cols = 4 + (int)nattr + (int)nmark;
    for (uint32_t i = 0; i < out->point_count; i++) {
        if (!next_line(&r, &line)) {
            snprintf(err, errlen, "%s: truncated: %u of %u points", path, i, out->point_count);
            res = VFX_ERR_FORMAT;
            goto done;
        }
        n = parse_numbers(line, v, TG_MAXCOL);
        if (n != cols) {
            snprintf(err, errlen, "%s:%d: point %u has %d numbers, expected %d", path, r.line, i,
                     n, cols);
            res = VFX_ERR_FORMAT;
            goto done;
        }
        if (i == 0) {
            if (v[0] != 0 && v[0] != 1) {
                snprintf(err, errlen, "%s:%d: first point index %g is neither 0 nor 1", path,
                         r.line, v[0]);
                res = VFX_ERR_FORMAT;
                goto done;
            }
            base = (int)v[0];
        }
        if (v[0] != (double)i + base) {
            snprintf(err, errlen, "%s:%d: point index %g, expected %u", path, r.line, v[0],
                     i + base);
            res = VFX_ERR_FORMAT;
            goto done;
        }
        /* Checked here, as float32, so the message has the file and line (1e39 is finite as a
         * double and Inf as the float the renderer uses). */
        for (int k = 0; k < 3; k++) {
            out->points[3 * (size_t)i + k] = (float)v[1 + k];
            if (!isfinite(out->points[3 * (size_t)i + k])) {
                snprintf(err, errlen, "%s:%d: point %u coordinate %c = %g is not finite as float32",
                         path, r.line, i, "xyz"[k], v[1 + k]);
                res = VFX_ERR_NUMERIC;
                goto done;
            }
        }
        if (attr_index >= 0) {
            out->scalar[i] = (float)v[4 + attr_index];
            if (!isfinite(out->scalar[i])) {
                snprintf(err, errlen, "%s:%d: point %u attribute %d = %g is not finite as float32",
                         path, r.line, i, attr_index, v[4 + attr_index]);
                res = VFX_ERR_NUMERIC;
                goto done;
            }
        }
    }

    snprintf(path, plen + 8, "%s.ele", path_base);
    if ((res = read_whole(path, &elebuf, &sz, err, errlen)))
        goto done;
    r = (tg_reader){elebuf, elebuf, 0, path};
    if (!next_line(&r, &line) || (n = parse_numbers(line, v, TG_MAXCOL)) < 1) {
        snprintf(err, errlen, "%s: missing or bad header line", path);
        res = VFX_ERR_FORMAT;
        goto done;
    }
    double nt = v[0], npt = n > 1 ? v[1] : 4, neattr = n > 2 ? v[2] : 0;
    if (nt < 1 || nt > 1e9 || (npt != 4 && npt != 10) || neattr < 0 || neattr > TG_MAXCOL - 12 ||
        !whole(nt) || !whole(neattr)) {
        snprintf(err, errlen, "%s:%d: bad header (tetrahedra %g, nodes per tet %g, attributes %g)",
                 path, r.line, nt, npt, neattr);
        res = VFX_ERR_FORMAT;
        goto done;
    }
    if (nt > RT_VOLUME_MAX_TETS) {
        snprintf(err, errlen, "%s: header claims %.0f tetrahedra, above the cap of %u "
                 "(RT_VOLUME_MAX_TETS)", path, nt, RT_VOLUME_MAX_TETS);
        res = VFX_ERR_FORMAT;
        goto done;
    }
    /* Same bound for tetrahedra. */
    if (nt > (double)sz / 2) {
        snprintf(err, errlen, "%s: truncated: header claims %g tetrahedra, file has %zu bytes",
                 path, nt, sz);
        res = VFX_ERR_FORMAT;
        goto done;
    }
    out->tet_count = (uint32_t)nt;
    out->tets = malloc(sizeof(uint32_t) * 4 * (size_t)nt);
    if (!out->tets) {
        snprintf(err, errlen, "%s: out of memory for %u tetrahedra", path, out->tet_count);
        res = VFX_ERR_OUT_OF_MEMORY;
        goto done;
    }
    cols = 1 + (int)npt + (int)neattr;
    for (uint32_t t = 0; t < out->tet_count; t++) {
        if (!next_line(&r, &line)) {
            snprintf(err, errlen, "%s: truncated: %u of %u tetrahedra", path, t, out->tet_count);
            res = VFX_ERR_FORMAT;
            goto done;
        }
        n = parse_numbers(line, v, TG_MAXCOL);
        if (n != cols) {
            snprintf(err, errlen, "%s:%d: tetrahedron %u has %d numbers, expected %d", path,
                     r.line, t, n, cols);
            res = VFX_ERR_FORMAT;
            goto done;
        }
        for (int k = 0; k < 4; k++) {
            double idx = v[1 + k] - base;
            if (!(idx >= 0 && idx < np) || idx != (double)(uint32_t)idx) {
                snprintf(err, errlen, "%s:%d: tetrahedron %u vertex %d index %g out of range "
                         "(%u points, %d-based)", path, r.line, t, k, v[1 + k], out->point_count,
                         base);
                res = VFX_ERR_FORMAT;
                goto done;
            }
            out->tets[4 * (size_t)t + k] = (uint32_t)idx;
        }
    }
    char inner[256] = "";
    res = rt_result_from_tet(tet_validate(out, inner, sizeof inner));
    if (res)
        snprintf(err, errlen, "%s.node/.ele: %s", path_base, inner);
done:
    if (res != VFX_OK)
        tet_mesh_free(out);
    free(nodebuf);
    free(elebuf);
    free(path);
    return res;
}
