/* volume_file_vtu.c — VTK XML UnstructuredGrid reader (expat + zlib). Appended raw data is not XML,
 * so expat is fed only the text before <AppendedData> (never finalised) and the arrays are then
 * decoded from the bytes after its '_' marker. */
#include "scene/volume_file.h"

#include <expat.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

enum { SEC_NONE, SEC_POINTS, SEC_CELLS, SEC_POINTDATA };
enum { T_BAD, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_I64, T_U64, T_F32, T_F64 };
enum { F_ASCII, F_BINARY, F_APPENDED };
#define VTU_MAXARR 64

typedef struct {
    char name[64];
    int section, type, format, ncomp;
    size_t offset;            /* appended */
    size_t text_begin, text_end; /* inline text: byte range in the input */
} vtu_array;

typedef struct {
    XML_Parser parser;
    const char *data;
    size_t size;
    int section, in_piece, pieces;
    double npoints, ncells;
    int header64, zlib, appended_base64, has_grid;
    vtu_array arr[VTU_MAXARR];
    int narr, cur;
    char *err;
    size_t errlen;
    int failed;
} vtu_state;

static int type_of(const char *s)
{
    static const char *names[] = {"", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32",
                                  "Int64", "UInt64", "Float32", "Float64"};
    for (int i = 1; i <= T_F64; i++)
        if (!strcmp(s, names[i]))
            return i;
    return T_BAD;
}
static size_t type_size(int t)
{
    static const size_t sz[] = {0, 1, 1, 2, 2, 4, 4, 8, 8, 4, 8};
    return sz[t];
}

static void fail(vtu_state *s, const char *msg)
{
    if (!s->failed)
        snprintf(s->err, s->errlen, "line %lu: %s",
                 (unsigned long)XML_GetCurrentLineNumber(s->parser), msg);
    s->failed = 1;
    XML_StopParser(s->parser, XML_FALSE);
}

static const char *attr(const XML_Char **a, const char *key)
{
    for (; a[0]; a += 2)
        if (!strcmp(a[0], key))
            return a[1];
    return NULL;
}

static void XMLCALL on_start(void *ud, const XML_Char *el, const XML_Char **a)
{
    vtu_state *s = ud;
    if (!strcmp(el, "VTKFile")) {
        const char *t = attr(a, "type"), *h = attr(a, "header_type"), *c = attr(a, "compressor");
        const char *bo = attr(a, "byte_order");
        if (!t || strcmp(t, "UnstructuredGrid"))
            return fail(s, "VTKFile type is not UnstructuredGrid");
        if (bo && strcmp(bo, "LittleEndian"))
            return fail(s, "byte_order BigEndian not supported");
        s->header64 = h && !strcmp(h, "UInt64");
        if (h && !s->header64 && strcmp(h, "UInt32"))
            return fail(s, "header_type must be UInt32 or UInt64");
        if (c && strcmp(c, "vtkZLibDataCompressor"))
            return fail(s, "only vtkZLibDataCompressor is supported");
        s->zlib = c != NULL;
    } else if (!strcmp(el, "UnstructuredGrid")) {
        s->has_grid = 1;
    } else if (!strcmp(el, "Piece")) {
        if (++s->pieces > 1)
            return fail(s, "more than one Piece is not supported");
        const char *p = attr(a, "NumberOfPoints"), *c = attr(a, "NumberOfCells");
        char *e1 = NULL, *e2 = NULL;
        s->npoints = p ? strtod(p, &e1) : -1;
        s->ncells = c ? strtod(c, &e2) : -1;
        if (!p || !c || *e1 || *e2 || !(s->npoints >= 1 && s->npoints < 4e9) ||
            !(s->ncells >= 1 && s->ncells < 1e9) || s->npoints != floor(s->npoints) ||
            s->ncells != floor(s->ncells))
            return fail(s, "Piece NumberOfPoints/NumberOfCells missing or out of range");
    } else if (!strcmp(el, "Points")) {
        s->section = SEC_POINTS;
    } else if (!strcmp(el, "Cells")) {
        s->section = SEC_CELLS;
    } else if (!strcmp(el, "PointData")) {
        s->section = SEC_POINTDATA;
    } else if (!strcmp(el, "DataArray")) {
        if (s->narr >= VTU_MAXARR)
            return fail(s, "too many DataArrays");
        vtu_array *d = &s->arr[s->narr];
        memset(d, 0, sizeof *d);
        const char *n = attr(a, "Name"), *t = attr(a, "type"), *f = attr(a, "format");
        const char *nc = attr(a, "NumberOfComponents"), *o = attr(a, "offset");
        snprintf(d->name, sizeof d->name, "%s", n ? n : "");
        d->section = s->section;
        d->type = t ? type_of(t) : T_BAD;
        if (d->type == T_BAD)
            return fail(s, "DataArray type missing or unknown");
        d->ncomp = nc ? atoi(nc) : 1;
        if (d->ncomp < 1 || d->ncomp > 9)
            return fail(s, "DataArray NumberOfComponents out of range 1..9");
        if (!f || !strcmp(f, "ascii"))
            d->format = F_ASCII;
        else if (!strcmp(f, "binary"))
            d->format = F_BINARY;
        else if (!strcmp(f, "appended")) {
            d->format = F_APPENDED;
            char *e = NULL;
            double off = o ? strtod(o, &e) : -1;
            if (!o || *e || off < 0 || off > 1e18)
                return fail(s, "appended DataArray without a valid offset");
            d->offset = (size_t)off;
        } else
            return fail(s, "DataArray format unknown");
        d->text_begin = d->text_end = 0;
        s->cur = s->narr++;
    } else if (!strcmp(el, "AppendedData")) {
        const char *e = attr(a, "encoding");
        s->appended_base64 = e && !strcmp(e, "base64");
    }
}

static void XMLCALL on_end(void *ud, const XML_Char *el)
{
    vtu_state *s = ud;
    if (!strcmp(el, "Points") || !strcmp(el, "Cells") || !strcmp(el, "PointData"))
        s->section = SEC_NONE;
    else if (!strcmp(el, "DataArray"))
        s->cur = -1;
}

static void XMLCALL on_text(void *ud, const XML_Char *txt, int len)
{
    vtu_state *s = ud;
    (void)txt;
    if (s->cur < 0 || len <= 0)
        return;
    /* Record the byte range in the input: entity-free numeric/base64 text maps 1:1. */
    vtu_array *d = &s->arr[s->cur];
    size_t pos = (size_t)XML_GetCurrentByteIndex(s->parser);
    if (d->text_begin == d->text_end)
        d->text_begin = pos;
    d->text_end = pos + (size_t)len;
}

/* Decodes base64 from [src, src+n), skipping whitespace; '=' padding ends a 4-char group and
 * decoding resumes, so separately encoded header and data blocks concatenate. Returns bytes
 * written or (size_t)-1 on an invalid character. */
static size_t b64_decode(const char *src, size_t n, unsigned char *dst, int *bad)
{
    *bad = 0;
    size_t o = 0;
    unsigned v = 0;
    int k = 0, pad = 0;
    for (size_t i = 0; i < n; i++) {
        char c = src[i];
        int x;
        if (c >= 'A' && c <= 'Z') x = c - 'A';
        else if (c >= 'a' && c <= 'z') x = c - 'a' + 26;
        else if (c >= '0' && c <= '9') x = c - '0' + 52;
        else if (c == '+') x = 62;
        else if (c == '/') x = 63;
        else if (c == '=') { x = 0; pad++; }
        else if (c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
        else { *bad = 1; return o; }
        if (pad && c != '=') { *bad = 1; return o; }
        v = (v << 6) | (unsigned)x;
        if (++k == 4) {
            unsigned char b[3] = {(unsigned char)(v >> 16), (unsigned char)(v >> 8),
                                  (unsigned char)v};
            int keep = 3 - pad;
            if (keep < 1) { *bad = 1; return o; }
            for (int j = 0; j < keep; j++)
                dst[o++] = b[j];
            v = 0;
            k = 0;
            pad = 0;
        }
    }
    if (k)
        *bad = 1;
    return o;
}

static uint64_t rd_header(const unsigned char *p, int h64)
{
    uint64_t v = 0;
    int n = h64 ? 8 : 4;
    for (int i = n - 1; i >= 0; i--)
        v = (v << 8) | p[i];
    return v;
}

/* From encoded-binary bytes [b, b+n) (header + payload), produce the raw payload of want bytes. */
static vfx_result unpack(vtu_state *s, const unsigned char *b, size_t n, size_t want,
                         unsigned char **out, const char *what)
{
    size_t hs = s->header64 ? 8 : 4;
    *out = NULL;
    if (!s->zlib) {
        if (n < hs) goto trunc;
        uint64_t len = rd_header(b, s->header64);
        if (len != want) {
            snprintf(s->err, s->errlen, "%s: block holds %llu bytes, expected %zu", what,
                     (unsigned long long)len, want);
            return VFX_ERR_FORMAT;
        }
        if (n - hs < want) goto trunc;
        *out = malloc(want ? want : 1);
        if (!*out) return VFX_ERR_OUT_OF_MEMORY;
        memcpy(*out, b + hs, want);
        return VFX_OK;
    }
    if (n < 3 * hs) goto trunc;
    uint64_t nb = rd_header(b, s->header64), bs = rd_header(b + hs, s->header64);
    uint64_t last = rd_header(b + 2 * hs, s->header64);
    if (nb > (n - 3 * hs) / hs || bs == 0 || last > bs) {
        snprintf(s->err, s->errlen, "%s: bad zlib block header (%llu blocks of %llu)", what,
                 (unsigned long long)nb, (unsigned long long)bs);
        return VFX_ERR_FORMAT;
    }
    uint64_t total = nb == 0 ? 0 : (nb - 1) * bs + (last ? last : bs);
    if (total != want) {
        snprintf(s->err, s->errlen, "%s: compressed data holds %llu bytes, expected %zu", what,
                 (unsigned long long)total, want);
        return VFX_ERR_FORMAT;
    }
    *out = malloc(want ? want : 1);
    if (!*out) return VFX_ERR_OUT_OF_MEMORY;
    size_t pos = 3 * hs + nb * hs, o = 0;
    for (uint64_t i = 0; i < nb; i++) {
        uint64_t cs = rd_header(b + 3 * hs + i * hs, s->header64);
        if (cs > n - pos) { free(*out); *out = NULL; goto trunc; }
        uLongf dl = (uLongf)(i + 1 == nb && last ? last : bs);
        uLongf expect = dl;
        int zr = uncompress(*out + o, &dl, b + pos, (uLong)cs);
        if (zr != Z_OK || dl != expect) {
            snprintf(s->err, s->errlen, "%s: zlib block %llu failed to inflate (%s)", what,
                     (unsigned long long)i, zr == Z_OK ? "short block" : zError(zr));
            free(*out);
            *out = NULL;
            return VFX_ERR_FORMAT;
        }
        o += dl;
        pos += cs;
    }
    return VFX_OK;
trunc:
    snprintf(s->err, s->errlen, "%s: data truncated", what);
    return VFX_ERR_FORMAT;
}

/* Reads count*ncomp values of an array as doubles into *vals (malloc'd). */
static vfx_result read_array(vtu_state *s, const vtu_array *d, size_t count, double **vals,
                             size_t app_start)
{
    char what[128];
    snprintf(what, sizeof what, "DataArray '%s'", d->name);
    size_t nv = count * (size_t)d->ncomp, ts = type_size(d->type);
    double *v = malloc(sizeof(double) * (nv ? nv : 1));
    unsigned char *raw = NULL, *dec = NULL;
    vfx_result r = VFX_OK;
    if (!v) return VFX_ERR_OUT_OF_MEMORY;
    if (d->format == F_ASCII) {
        const char *p = s->data + d->text_begin, *e = s->data + d->text_end;
        for (size_t i = 0; i < nv; i++) {
            while (p < e && (*p == ' ' || *p == '\n' || *p == '\r' || *p == '\t')) p++;
            char buf[64];
            size_t k = 0;
            while (p < e && k < sizeof buf - 1 && !(*p == ' ' || *p == '\n' || *p == '\r' || *p == '\t'))
                buf[k++] = *p++;
            buf[k] = 0;
            char *end;
            v[i] = strtod(buf, &end);
            if (k == 0 || *end) {
                snprintf(s->err, s->errlen, "%s: value %zu of %zu %s", what, i, nv,
                         k ? "is not a number" : "missing (too few values)");
                free(v);
                return VFX_ERR_FORMAT;
            }
        }
        *vals = v;
        return VFX_OK;
    }
    size_t want = nv * ts;
    if (d->format == F_BINARY || s->appended_base64) {
        const char *src;
        size_t n;
        if (d->format == F_BINARY) {
            src = s->data + d->text_begin;
            n = d->text_end - d->text_begin;
        } else {
            if (app_start + d->offset > s->size) goto trunc;
            src = s->data + app_start + d->offset;
            n = s->size - app_start - d->offset;
            const char *lt = memchr(src, '<', n);
            if (lt) n = (size_t)(lt - src);
        }
        dec = malloc(n / 4 * 3 + 4);
        if (!dec) { free(v); return VFX_ERR_OUT_OF_MEMORY; }
        int bad;
        size_t dn = b64_decode(src, n, dec, &bad);
        /* Appended base64 runs on into the next arrays: a bad character there only matters
         * when this array's bytes are not complete before it. */
        if (bad && d->format == F_BINARY) {
            snprintf(s->err, s->errlen, "%s: invalid base64", what);
            r = VFX_ERR_FORMAT;
            goto out;
        }
        r = unpack(s, dec, dn, want, &raw, what);
        if (r == VFX_ERR_FORMAT && bad)
            snprintf(s->err, s->errlen, "%s: invalid base64", what);
    } else {
        if (app_start == 0 || app_start + d->offset > s->size) goto trunc;
        r = unpack(s, (const unsigned char *)s->data + app_start + d->offset,
                   s->size - app_start - d->offset, want, &raw, what);
    }
    if (r != VFX_OK) goto out;
    for (size_t i = 0; i < nv; i++) {
        const unsigned char *p = raw + i * ts;
        switch (d->type) {
        case T_I8: v[i] = (int8_t)p[0]; break;
        case T_U8: v[i] = p[0]; break;
        case T_I16: { int16_t x; memcpy(&x, p, 2); v[i] = x; } break;
        case T_U16: { uint16_t x; memcpy(&x, p, 2); v[i] = x; } break;
        case T_I32: { int32_t x; memcpy(&x, p, 4); v[i] = x; } break;
        case T_U32: { uint32_t x; memcpy(&x, p, 4); v[i] = x; } break;
        case T_I64: { int64_t x; memcpy(&x, p, 8); v[i] = (double)x; } break;
        case T_U64: { uint64_t x; memcpy(&x, p, 8); v[i] = (double)x; } break;
        case T_F32: { float x; memcpy(&x, p, 4); v[i] = x; } break;
        default: { double x; memcpy(&x, p, 8); v[i] = x; } break;
        }
    }
out:
    free(dec);
    free(raw);
    if (r != VFX_OK) free(v);
    else *vals = v;
    return r;
trunc:
    free(v);
    snprintf(s->err, s->errlen, "%s: appended offset %zu beyond the end of the file", what,
             d->offset);
    return VFX_ERR_FORMAT;
}

static const vtu_array *find(const vtu_state *s, int section, const char *name)
{
    for (int i = 0; i < s->narr; i++)
        if (s->arr[i].section == section && (!name || !strcmp(s->arr[i].name, name)))
            return &s->arr[i];
    return NULL;
}

vfx_result rt_volume_load_vtu_mem(const void *data, size_t size, const char *scalar_name,
                                tet_mesh *out, char *err, size_t errlen)
{
    if (!data || !out || !err) {
        if (err) snprintf(err, errlen, "NULL argument");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    memset(out, 0, sizeof *out);
    if (size == 0) {
        snprintf(err, errlen, "empty file");
        return VFX_ERR_FORMAT;
    }
    vtu_state *s = calloc(1, sizeof *s);
    if (!s) return VFX_ERR_OUT_OF_MEMORY;
    s->data = data;
    s->size = size;
    s->cur = -1;
    s->err = err;
    s->errlen = errlen;
    vfx_result r = VFX_OK;
    double *pts = NULL, *conn = NULL, *offs = NULL, *types = NULL, *sc = NULL;
    size_t app_start = 0, xml_len = size;
    /* Appended section: expat only sees the XML before it. */
    const char *ad = NULL;
    for (size_t i = 0; i + 13 <= size; i++)
        if (((const char *)data)[i] == '<' && !memcmp((const char *)data + i, "<AppendedData", 13)) {
            ad = (const char *)data + i;
            break;
        }
    if (ad) {
        const char *gt = memchr(ad, '>', size - (size_t)(ad - (const char *)data));
        const char *us = gt ? memchr(gt, '_', size - (size_t)(gt - (const char *)data)) : NULL;
        if (!us) {
            snprintf(err, errlen, "AppendedData without its '_' marker");
            r = VFX_ERR_FORMAT;
            goto done;
        }
        app_start = (size_t)(us - (const char *)data) + 1;
        xml_len = (size_t)(gt + 1 - (const char *)data);
    }
    s->parser = XML_ParserCreate(NULL);
    if (!s->parser) { r = VFX_ERR_OUT_OF_MEMORY; goto done; }
    XML_SetUserData(s->parser, s);
    XML_SetElementHandler(s->parser, on_start, on_end);
    XML_SetCharacterDataHandler(s->parser, on_text);
    if (xml_len > (size_t)0x7fffffff) { snprintf(err, errlen, "file too large"); r = VFX_ERR_FORMAT; goto done; }
    if (XML_Parse(s->parser, data, (int)xml_len, ad ? XML_FALSE : XML_TRUE) == XML_STATUS_ERROR) {
        if (!s->failed)
            snprintf(err, errlen, "not valid XML: line %lu: %s",
                     (unsigned long)XML_GetCurrentLineNumber(s->parser),
                     XML_ErrorString(XML_GetErrorCode(s->parser)));
        r = VFX_ERR_FORMAT;
        goto done;
    }
    if (!s->has_grid || s->pieces != 1) {
        snprintf(err, errlen, "no UnstructuredGrid Piece found");
        r = VFX_ERR_FORMAT;
        goto done;
    }
    const vtu_array *ap = find(s, SEC_POINTS, NULL), *ac = find(s, SEC_CELLS, "connectivity");
    const vtu_array *ao = find(s, SEC_CELLS, "offsets"), *at = find(s, SEC_CELLS, "types");
    if (!ap || !ac || !ao || !at) {
        snprintf(err, errlen, "missing %s", !ap ? "Points DataArray" : !ac ? "Cells connectivity"
                 : !ao ? "Cells offsets" : "Cells types");
        r = VFX_ERR_FORMAT;
        goto done;
    }
    if (ap->ncomp != 3 || (ap->type != T_F32 && ap->type != T_F64)) {
        snprintf(err, errlen, "Points must be 3-component Float32/Float64");
        r = VFX_ERR_FORMAT;
        goto done;
    }
    const vtu_array *as = NULL;
    if (scalar_name) {
        as = find(s, SEC_POINTDATA, scalar_name);
        if (!as) {
            int n = snprintf(err, errlen, "point field '%s' not found; present:", scalar_name);
            for (int i = 0; i < s->narr && n >= 0 && (size_t)n < errlen; i++)
                if (s->arr[i].section == SEC_POINTDATA)
                    n += snprintf(err + n, errlen - (size_t)n, " %s", s->arr[i].name);
            r = VFX_ERR_NOT_FOUND;
            goto done;
        }
    }
    size_t np = (size_t)s->npoints, nc = (size_t)s->ncells;
    if ((r = read_array(s, ap, np, &pts, app_start)) ||
        (r = read_array(s, at, nc, &types, app_start)) ||
        (r = read_array(s, ao, nc, &offs, app_start)) ||
        (r = read_array(s, ac, 4 * nc, &conn, app_start)))
        goto done;
    for (size_t c = 0; c < nc; c++) {
        if (types[c] != 10) {
            snprintf(err, errlen, "cell %zu has VTK type %g; only tetrahedra (VTK_TETRA = 10) "
                     "are supported", c, types[c]);
            r = VFX_ERR_UNSUPPORTED;
            goto done;
        }
        if (offs[c] != 4.0 * (double)(c + 1)) {
            snprintf(err, errlen, "cell %zu: offset %g, expected %zu for 4-vertex cells", c,
                     offs[c], 4 * (c + 1));
            r = VFX_ERR_FORMAT;
            goto done;
        }
    }
    if (as && (r = read_array(s, as, np, &sc, app_start)))
        goto done;
    out->point_count = (uint32_t)np;
    out->tet_count = (uint32_t)nc;
    out->points = malloc(sizeof(float) * 3 * np);
    out->tets = malloc(sizeof(uint32_t) * 4 * nc);
    if (as) out->scalar = malloc(sizeof(float) * np);
    if (!out->points || !out->tets || (as && !out->scalar)) { r = VFX_ERR_OUT_OF_MEMORY; goto done; }
    for (size_t i = 0; i < 3 * np; i++)
        out->points[i] = (float)pts[i];
    for (size_t i = 0; i < 4 * nc; i++) {
        if (!(conn[i] >= 0 && conn[i] < (double)np)) {
            snprintf(err, errlen, "cell %zu vertex %zu: index %g out of range (%zu points)",
                     i / 4, i % 4, conn[i], np);
            r = VFX_ERR_FORMAT;
            goto done;
        }
        out->tets[i] = (uint32_t)conn[i];
    }
    if (as) {
        snprintf(out->scalar_name, sizeof out->scalar_name, "%s%.60s%s", as->ncomp > 1 ? "|" : "",
                 as->name, as->ncomp > 1 ? "|" : "");
        for (size_t i = 0; i < np; i++) {
            double m = 0;
            if (as->ncomp == 1)
                m = sc[i];
            else
                for (int k = 0; k < as->ncomp; k++)
                    m += sc[i * (size_t)as->ncomp + k] * sc[i * (size_t)as->ncomp + k];
            out->scalar[i] = (float)(as->ncomp == 1 ? m : sqrt(m));
        }
    }
    r = tet_validate(out, err, errlen);
done:
    if (r != VFX_OK) tet_mesh_free(out);
    if (s->parser) XML_ParserFree(s->parser);
    free(s);
    free(pts); free(conn); free(offs); free(types); free(sc);
    return r;
}

vfx_result rt_volume_load_vtu(const char *path, const char *scalar_name, tet_mesh *out,
                            char *err, size_t errlen)
{
    if (!path || !out) {
        snprintf(err, errlen, "NULL argument");
        return VFX_ERR_INVALID_ARGUMENT;
    }
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, errlen, "%s: cannot open", path);
        return VFX_ERR_IO;
    }
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (!buf || fread(buf, 1, (size_t)n, f) != (size_t)n) {
        fclose(f);
        free(buf);
        snprintf(err, errlen, "%s: cannot read", path);
        return VFX_ERR_IO;
    }
    fclose(f);
    char inner[256];
    vfx_result r = rt_volume_load_vtu_mem(buf, (size_t)n, scalar_name, out, inner, sizeof inner);
    if (r != VFX_OK)
        snprintf(err, errlen, "%s: %s", path, inner);
    free(buf);
    return r;
}
