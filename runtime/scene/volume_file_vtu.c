/* volume_file_vtu.c — VTK XML UnstructuredGrid reader (expat + zlib). Appended raw data is not XML,
 * so expat is fed only the text before <AppendedData> (never finalised) and the arrays are then
 * decoded from the bytes after its '_' marker. */
#include "scene/volume_file.h"
#include "core/file.h"

#include <expat.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

_Static_assert(TET_OK == (int)VFX_OK && TET_ERR_INVALID_ARGUMENT == (int)VFX_ERR_INVALID_ARGUMENT &&
                   TET_ERR_OUT_OF_MEMORY == (int)VFX_ERR_OUT_OF_MEMORY &&
                   TET_ERR_FORMAT == (int)VFX_ERR_FORMAT && TET_ERR_NUMERIC == (int)VFX_ERR_NUMERIC,
               "tet_result and vfx_result codes differ (rt_result_from_tet)");

enum { SEC_NONE, SEC_POINTS, SEC_CELLS, SEC_POINTDATA };
enum { T_BAD, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_I64, T_U64, T_F32, T_F64 };
enum { F_ASCII, F_BINARY, F_APPENDED };
#define VTU_MAXARR 64

typedef struct {
    char name[64];
    int section, type, format, ncomp;
    size_t offset;            /* appended */
    size_t text_begin, text_end; /* inline text: byte range in the input */
    double tuples;            /* NumberOfTuples when given, else -1 */
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
    size_t decoded; /* bytes decoded or inflated so far, against RT_VTU_MAX_DECODED_BYTES */
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

static const char *const TYPE_NAMES[] = {"?", "Int8", "UInt8", "Int16", "UInt16", "Int32",
                                          "UInt32", "Int64", "UInt64", "Float32", "Float64"};

/* Every error path writes its text through here (the caller prints err whatever the code). */
static vfx_result errf(vtu_state *s, vfx_result r, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static vfx_result errf(vtu_state *s, vfx_result r, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s->err, s->errlen, fmt, ap);
    va_end(ap);
    return r;
}

/* A whole-string decimal number (strtod), or -1 when absent; *ok 0 when present but malformed. */
static double attr_number(const char *v, int *ok)
{
    if (!v)
        return -1;
    char *e = NULL;
    double x = strtod(v, &e);
    *ok = e != v && *e == 0 && isfinite(x);
    return x;
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
        int ok1 = 1, ok2 = 1;
        s->npoints = attr_number(p, &ok1);
        s->ncells = attr_number(c, &ok2);
        if (!p || !c || !ok1 || !ok2 || !(s->npoints >= 1) || !(s->ncells >= 1) ||
            s->npoints != floor(s->npoints) || s->ncells != floor(s->ncells))
            return fail(s, "Piece NumberOfPoints/NumberOfCells missing or out of range");
        char msg[160];
        if (s->npoints > RT_VOLUME_MAX_POINTS || s->ncells > RT_VOLUME_MAX_TETS) {
            snprintf(msg, sizeof msg, "Piece %s %.0f above the cap of %u (%s)",
                     s->npoints > RT_VOLUME_MAX_POINTS ? "NumberOfPoints" : "NumberOfCells",
                     s->npoints > RT_VOLUME_MAX_POINTS ? s->npoints : s->ncells,
                     s->npoints > RT_VOLUME_MAX_POINTS ? RT_VOLUME_MAX_POINTS : RT_VOLUME_MAX_TETS,
                     s->npoints > RT_VOLUME_MAX_POINTS ? "RT_VOLUME_MAX_POINTS" : "RT_VOLUME_MAX_TETS");
            return fail(s, msg);
        }
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
        int okc = 1, okt = 1;
        double ncd = nc ? attr_number(nc, &okc) : 1;
        if (!okc || !(ncd >= 1 && ncd <= 9) || ncd != floor(ncd)) {
            char msg[160];
            snprintf(msg, sizeof msg, "DataArray '%.64s' NumberOfComponents \"%.32s\" is not an "
                     "integer in 1..9", d->name, nc);
            return fail(s, msg);
        }
        d->ncomp = (int)ncd;
        d->tuples = attr_number(attr(a, "NumberOfTuples"), &okt);
        if (!okt || (d->tuples >= 0 && d->tuples != floor(d->tuples)))
            return fail(s, "DataArray NumberOfTuples is not an integer");
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
 * decoding resumes, so separately encoded header and data blocks concatenate. Stops once `limit`
 * bytes are out (dst holds limit + 3). Returns bytes written; *bad on an invalid character. */
static size_t b64_decode(const char *src, size_t n, unsigned char *dst, size_t limit, int *bad)
{
    *bad = 0;
    size_t o = 0;
    unsigned v = 0;
    int k = 0, pad = 0;
    for (size_t i = 0; i < n && o < limit; i++) {
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
    if (k && o < limit)
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

static uint64_t sat_add(uint64_t a, uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; }
static uint64_t sat_mul(uint64_t a, uint64_t b) { return b && a > UINT64_MAX / b ? UINT64_MAX : a * b; }

/* Bytes of encoded block (header + payload) that the headers in b[0..n) say it takes; more than
 * n when the prefix is too short to tell (then call again with that many). */
static uint64_t block_bytes(const vtu_state *s, const unsigned char *b, size_t n)
{
    uint64_t hs = s->header64 ? 8 : 4;
    if (!s->zlib)
        return n < hs ? hs : sat_add(hs, rd_header(b, s->header64));
    if (n < 3 * hs)
        return 3 * hs;
    uint64_t nb = rd_header(b, s->header64), head = sat_add(3 * hs, sat_mul(nb, hs));
    if (n < head)
        return head;
    uint64_t total = head;
    for (uint64_t i = 0; i < nb; i++)
        total = sat_add(total, rd_header(b + 3 * hs + i * hs, s->header64));
    return total;
}

/* From encoded-binary bytes [b, b+n) (header + payload), produce the raw payload of want bytes
 * (malloc'd) and the bytes of b it used. Every claim is checked against n before allocating. */
static vfx_result unpack(vtu_state *s, const unsigned char *b, size_t n, size_t want,
                         unsigned char **out, size_t *used, const char *what)
{
    size_t hs = s->header64 ? 8 : 4;
    *out = NULL;
    if (!s->zlib) {
        if (n < hs) goto trunc;
        uint64_t len = rd_header(b, s->header64);
        if (len != want)
            return errf(s, VFX_ERR_FORMAT, "%s: block holds %llu bytes, expected %zu", what,
                        (unsigned long long)len, want);
        if (n - hs < want) goto trunc;
        *out = malloc(want ? want : 1);
        if (!*out)
            return errf(s, VFX_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu bytes", what, want);
        memcpy(*out, b + hs, want);
        *used = hs + want;
        return VFX_OK;
    }
    if (n < 3 * hs) goto trunc;
    uint64_t nb = rd_header(b, s->header64), bs = rd_header(b + hs, s->header64);
    uint64_t last = rd_header(b + 2 * hs, s->header64);
    if (nb > (n - 3 * hs) / hs || bs == 0 || last > bs)
        return errf(s, VFX_ERR_FORMAT, "%s: bad zlib block header (%llu blocks of %llu)", what,
                    (unsigned long long)nb, (unsigned long long)bs);
    uint64_t total = nb == 0 ? 0 : sat_add(sat_mul(nb - 1, bs), last ? last : bs);
    if (total != want)
        return errf(s, VFX_ERR_FORMAT, "%s: compressed data holds %llu bytes, expected %zu", what,
                    (unsigned long long)total, want);
    /* What the file can hold: every compressed block present, and none claiming to inflate
     * beyond the deflate ratio, before the output is allocated. */
    size_t pos = 3 * hs + nb * hs;
    for (uint64_t i = 0; i < nb; i++) {
        uint64_t cs = rd_header(b + 3 * hs + i * hs, s->header64);
        uint64_t dl = i + 1 == nb && last ? last : bs;
        if (cs > n - pos) goto trunc;
        if (dl > sat_mul(cs, RT_ZLIB_MAX_RATIO))
            return errf(s, VFX_ERR_FORMAT, "%s: zlib block %llu of %llu bytes claims %llu "
                        "bytes inflated, beyond the deflate ratio of %u", what,
                        (unsigned long long)i, (unsigned long long)cs, (unsigned long long)dl,
                        RT_ZLIB_MAX_RATIO);
        pos += cs;
    }
    *out = malloc(want ? want : 1);
    if (!*out)
        return errf(s, VFX_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu bytes", what, want);
    pos = 3 * hs + nb * hs;
    size_t o = 0;
    for (uint64_t i = 0; i < nb; i++) {
        uint64_t cs = rd_header(b + 3 * hs + i * hs, s->header64);
        uLongf dl = (uLongf)(i + 1 == nb && last ? last : bs);
        uLongf expect = dl;
        int zr = uncompress(*out + o, &dl, b + pos, (uLong)cs);
        if (zr != Z_OK || dl != expect) {
            free(*out);
            *out = NULL;
            return errf(s, VFX_ERR_FORMAT, "%s: zlib block %llu failed to inflate (%s)", what,
                        (unsigned long long)i, zr == Z_OK ? "short block" : zError(zr));
        }
        o += dl;
        pos += cs;
    }
    *used = pos;
    return VFX_OK;
trunc:
    return errf(s, VFX_ERR_FORMAT, "%s: data truncated", what);
}

static int is_space(char c) { return c == ' ' || c == '\n' || c == '\r' || c == '\t'; }

/* One ASCII value: the token [p, q) of any length, whole, and for an integer type integral and
 * in the type's range. */
static vfx_result ascii_value(vtu_state *s, const vtu_array *d, const char *what, const char *p,
                              const char *q, size_t i, size_t nv, double *out)
{
    size_t len = (size_t)(q - p);
    char small[128], *tok = len < sizeof small ? small : malloc(len + 1);
    if (!tok)
        return errf(s, VFX_ERR_OUT_OF_MEMORY, "%s: out of memory for a %zu-byte value", what, len);
    memcpy(tok, p, len);
    tok[len] = 0;
    char *end;
    double x = strtod(tok, &end);
    vfx_result r = VFX_OK;
    char pos[64] = "";
    if (d->ncomp > 1)
        snprintf(pos, sizeof pos, " (tuple %zu component %zu)", i / (size_t)d->ncomp,
                 i % (size_t)d->ncomp);
    if (*end || end == tok)
        r = errf(s, VFX_ERR_FORMAT, "%s: value %zu of %zu%s \"%.32s%s\" is not a number", what, i,
                 nv, pos, tok, len > 32 ? "..." : "");
    else if (d->type < T_F32) {
        static const double lo[] = {0, -128, 0, -32768, 0, -2147483648.0, 0, -9223372036854775808.0, 0};
        static const double hi[] = {0, 127, 255, 32767, 65535, 2147483647.0, 4294967295.0,
                                    9223372036854775807.0, 18446744073709551615.0};
        if (x != floor(x) || x < lo[d->type] || x > hi[d->type])
            r = errf(s, VFX_ERR_FORMAT, "%s: value %zu of %zu%s \"%.32s%s\" is not an integer "
                     "of type %s", what, i, nv, pos, tok, len > 32 ? "..." : "",
                     TYPE_NAMES[d->type]);
    }
    if (tok != small)
        free(tok);
    *out = x;
    return r;
}

static vfx_result read_ascii(vtu_state *s, const vtu_array *d, const char *what, size_t nv,
                             double **vals)
{
    const char *p = s->data + d->text_begin, *e = s->data + d->text_end;
    size_t len = d->text_end - d->text_begin;
    /* Every value takes a character and a separator: a claim beyond that is refused before
     * allocating for it. */
    if (nv > len / 2 + 1)
        return errf(s, VFX_ERR_FORMAT, "%s: %zu values expected, its %zu bytes of text hold at "
                    "most %zu (too few values)", what, nv, len, len / 2 + 1);
    double *v = malloc(sizeof(double) * (nv ? nv : 1));
    if (!v)
        return errf(s, VFX_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu values", what, nv);
    for (size_t i = 0; i < nv; i++) {
        while (p < e && is_space(*p)) p++;
        const char *q = p;
        while (q < e && !is_space(*q)) q++;
        if (q == p) {
            free(v);
            return errf(s, VFX_ERR_FORMAT, "%s: value %zu of %zu missing (too few values)", what,
                        i, nv);
        }
        vfx_result r = ascii_value(s, d, what, p, q, i, nv, &v[i]);
        if (r) {
            free(v);
            return r;
        }
        p = q;
    }
    while (p < e && is_space(*p)) p++;
    if (p < e) {
        const char *q = p;
        while (q < e && !is_space(*q) && q - p < 32) q++;
        free(v);
        return errf(s, VFX_ERR_FORMAT, "%s: surplus values: %zu expected (count x "
                    "NumberOfComponents %d), value %zu is \"%.*s\"", what, nv, d->ncomp, nv,
                    (int)(q - p), p);
    }
    *vals = v;
    return VFX_OK;
}

/* Decodes base64 text [src, src+n) whole, or (appended, running on into the next arrays) far
 * enough for one encoded block (header + payload). */
static vfx_result b64_block(vtu_state *s, const char *src, size_t n, int whole, unsigned char **dec,
                            size_t *dn, int *bad, const char *what)
{
    size_t most = n / 4 * 3 + 3, limit = s->zlib ? 3 * (s->header64 ? 8 : 4) : (s->header64 ? 8 : 4);
    if (whole)
        limit = most;
    for (int pass = 0; pass < 4; pass++) {
        free(*dec);
        *dec = malloc((limit < most ? limit : most) + 3);
        if (!*dec)
            return errf(s, VFX_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu bytes", what, limit);
        *dn = b64_decode(src, n, *dec, limit, bad);
        uint64_t need = block_bytes(s, *dec, *dn);
        if (need <= *dn || *dn < limit || limit >= most)
            break; /* complete, or the text ended: unpack says which */
        limit = need < most ? (size_t)need : most;
    }
    return VFX_OK;
}

/* Reads count*ncomp values of an array as doubles into *vals (malloc'd). */
static vfx_result read_array(vtu_state *s, const vtu_array *d, size_t count, double **vals,
                             size_t app_start)
{
    char what[128];
    snprintf(what, sizeof what, "DataArray '%s'", d->name);
    *vals = NULL;
    if (d->tuples >= 0 && d->tuples != (double)count)
        return errf(s, VFX_ERR_FORMAT, "%s: NumberOfTuples %.0f, expected %zu", what, d->tuples,
                    count);
    size_t nv = count * (size_t)d->ncomp, ts = type_size(d->type);
    if (d->format == F_ASCII)
        return read_ascii(s, d, what, nv, vals);
    size_t want = nv * ts;
    if (want > RT_VTU_MAX_DECODED_BYTES - s->decoded)
        return errf(s, VFX_ERR_FORMAT, "%s: %zu bytes of data, above the cap of %u bytes decoded "
                    "per file (RT_VTU_MAX_DECODED_BYTES, %zu already)", what, want,
                    RT_VTU_MAX_DECODED_BYTES, s->decoded);
    s->decoded += want;
    unsigned char *raw = NULL, *dec = NULL;
    vfx_result r = VFX_OK;
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
        int bad = 0;
        size_t dn = 0, used = 0;
        if ((r = b64_block(s, src, n, d->format == F_BINARY, &dec, &dn, &bad, what)))
            goto out;
        /* Appended base64 runs on into the next arrays: a bad character there only matters
         * when this array's bytes are not complete before it. */
        if (bad && d->format == F_BINARY) {
            r = errf(s, VFX_ERR_FORMAT, "%s: invalid base64", what);
            goto out;
        }
        r = unpack(s, dec, dn, want, &raw, &used, what);
        if (r == VFX_ERR_FORMAT && bad)
            errf(s, r, "%s: invalid base64", what);
        if (!r && d->format == F_BINARY && used < dn) {
            r = errf(s, VFX_ERR_FORMAT, "%s: surplus data: %zu bytes after the %zu the block "
                     "header describes", what, dn - used, used);
            goto out;
        }
    } else {
        size_t used;
        if (app_start == 0 || app_start + d->offset > s->size) goto trunc;
        r = unpack(s, (const unsigned char *)s->data + app_start + d->offset,
                   s->size - app_start - d->offset, want, &raw, &used, what);
    }
    if (r != VFX_OK) goto out;
    double *v = malloc(sizeof(double) * (nv ? nv : 1));
    if (!v) {
        r = errf(s, VFX_ERR_OUT_OF_MEMORY, "%s: out of memory for %zu values", what, nv);
        goto out;
    }
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
    *vals = v;
out:
    free(dec);
    free(raw);
    return r;
trunc:
    return errf(s, VFX_ERR_FORMAT, "%s: appended offset %zu beyond the end of the file", what,
                d->offset);
}

static const vtu_array *find(const vtu_state *s, int section, const char *name)
{
    for (int i = 0; i < s->narr; i++)
        if (s->arr[i].section == section && (!name || !strcmp(s->arr[i].name, name)))
            return &s->arr[i];
    return NULL;
}

/* What the assembly needs from the file: its arrays, then their values decoded as doubles. */
typedef struct {
    const vtu_array *points, *conn, *offsets, *types, *scalar;
    size_t app_start; /* first byte after the AppendedData '_' marker (0: none) */
    double *pts, *cells, *sc;
} vtu_decoded;

/* Splits off the appended section (expat only sees the XML before it) and parses the XML. */
static vfx_result vtu_parse(vtu_state *s, vtu_decoded *d)
{
    const char *data = s->data;
    size_t size = s->size, xml_len = size;
    const char *ad = NULL;
    for (size_t i = 0; i + 13 <= size; i++)
        if (data[i] == '<' && !memcmp(data + i, "<AppendedData", 13)) {
            ad = data + i;
            break;
        }
    if (ad) {
        const char *gt = memchr(ad, '>', size - (size_t)(ad - data));
        const char *us = gt ? memchr(gt, '_', size - (size_t)(gt - data)) : NULL;
        if (!us)
            return errf(s, VFX_ERR_FORMAT, "AppendedData without its '_' marker");
        d->app_start = (size_t)(us - data) + 1;
        xml_len = (size_t)(gt + 1 - data);
    }
    s->parser = XML_ParserCreate(NULL);
    if (!s->parser)
        return errf(s, VFX_ERR_OUT_OF_MEMORY, "out of memory for the XML parser");
    XML_SetUserData(s->parser, s);
    XML_SetElementHandler(s->parser, on_start, on_end);
    XML_SetCharacterDataHandler(s->parser, on_text);
    if (xml_len > (size_t)0x7fffffff)
        return errf(s, VFX_ERR_FORMAT, "file too large");
    if (XML_Parse(s->parser, data, (int)xml_len, ad ? XML_FALSE : XML_TRUE) == XML_STATUS_ERROR) {
        if (!s->failed)
            errf(s, VFX_ERR_FORMAT, "not valid XML: line %lu: %s",
                 (unsigned long)XML_GetCurrentLineNumber(s->parser),
                 XML_ErrorString(XML_GetErrorCode(s->parser)));
        return VFX_ERR_FORMAT;
    }
    if (!s->has_grid || s->pieces != 1)
        return errf(s, VFX_ERR_FORMAT, "no UnstructuredGrid Piece found");
    return VFX_OK;
}

/* Finds the Points, the three Cells arrays and the named point field. */
static vfx_result vtu_find_arrays(vtu_state *s, const char *scalar_name, vtu_decoded *d)
{
    d->points = find(s, SEC_POINTS, NULL);
    d->conn = find(s, SEC_CELLS, "connectivity");
    d->offsets = find(s, SEC_CELLS, "offsets");
    d->types = find(s, SEC_CELLS, "types");
    if (!d->points || !d->conn || !d->offsets || !d->types)
        return errf(s, VFX_ERR_FORMAT, "missing %s", !d->points ? "Points DataArray"
                    : !d->conn ? "Cells connectivity" : !d->offsets ? "Cells offsets" : "Cells types");
    if (d->points->ncomp != 3 || (d->points->type != T_F32 && d->points->type != T_F64))
        return errf(s, VFX_ERR_FORMAT, "Points must be 3-component Float32/Float64");
    if (!scalar_name)
        return VFX_OK;
    d->scalar = find(s, SEC_POINTDATA, scalar_name);
    if (d->scalar)
        return VFX_OK;
    int n = snprintf(s->err, s->errlen, "point field '%s' not found; present:", scalar_name);
    for (int i = 0; i < s->narr && n >= 0 && (size_t)n < s->errlen; i++)
        if (s->arr[i].section == SEC_POINTDATA)
            n += snprintf(s->err + n, s->errlen - (size_t)n, " %s", s->arr[i].name);
    return VFX_ERR_NOT_FOUND;
}

static const char *vtk_cell_name(double t)
{
    static const struct { int type; const char *name; } names[] = {
        {1, "VTK_VERTEX"}, {2, "VTK_POLY_VERTEX"}, {3, "VTK_LINE"}, {4, "VTK_POLY_LINE"},
        {5, "VTK_TRIANGLE"}, {6, "VTK_TRIANGLE_STRIP"}, {7, "VTK_POLYGON"}, {8, "VTK_PIXEL"},
        {9, "VTK_QUAD"}, {11, "VTK_VOXEL"}, {12, "VTK_HEXAHEDRON"}, {13, "VTK_WEDGE"},
        {14, "VTK_PYRAMID"}, {21, "VTK_QUADRATIC_EDGE"}, {22, "VTK_QUADRATIC_TRIANGLE"},
        {23, "VTK_QUADRATIC_QUAD"}, {24, "VTK_QUADRATIC_TETRA"}, {25, "VTK_QUADRATIC_HEXAHEDRON"},
        {42, "VTK_POLYHEDRON"}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (t == names[i].type)
            return names[i].name;
    return "not a VTK linear or quadratic cell type this reader knows";
}

/* Types first, then offsets, then 4 vertices a cell: a hexahedron's 8 or a triangle's 3 would
 * otherwise surface as "surplus values" in the connectivity, not as the cell it is. */
static vfx_result vtu_read_cells(vtu_state *s, vtu_decoded *d)
{
    size_t nc = (size_t)s->ncells;
    double *types = NULL, *offs = NULL;
    vfx_result r = read_array(s, d->types, nc, &types, d->app_start);
    if (r)
        return r;
    size_t other = 0, first = nc;
    for (size_t c = 0; c < nc; c++)
        if (types[c] != 10 && other++ == 0)
            first = c;
    if (other) {
        r = errf(s, VFX_ERR_UNSUPPORTED, "cell %zu has VTK type %g (%s); only tetrahedra (VTK_TETRA = "
                 "10) are supported (%zu of the %zu cells are not tetrahedra)", first, types[first],
                 vtk_cell_name(types[first]), other, nc);
        free(types);
        return r;
    }
    free(types);
    if ((r = read_array(s, d->offsets, nc, &offs, d->app_start)))
        return r;
    for (size_t c = 0; c < nc && !r; c++)
        if (offs[c] != 4.0 * (double)(c + 1))
            r = errf(s, VFX_ERR_FORMAT, "cell %zu: offset %g, expected %zu for 4-vertex cells", c,
                     offs[c], 4 * (c + 1));
    free(offs);
    return r ? r : read_array(s, d->conn, 4 * nc, &d->cells, d->app_start);
}

/* Builds the mesh from the decoded arrays: float32 points, checked indices, the scalar (a
 * vector field's magnitude), then tet_validate. */
static vfx_result vtu_assemble(vtu_state *s, const vtu_decoded *d, tet_mesh *out)
{
    size_t np = (size_t)s->npoints, nc = (size_t)s->ncells;
    const vtu_array *as = d->scalar;
    out->point_count = (uint32_t)np;
    out->tet_count = (uint32_t)nc;
    out->points = malloc(sizeof(float) * 3 * np);
    out->tets = malloc(sizeof(uint32_t) * 4 * nc);
    if (as) out->scalar = malloc(sizeof(float) * np);
    if (!out->points || !out->tets || (as && !out->scalar))
        return errf(s, VFX_ERR_OUT_OF_MEMORY, "out of memory for %zu points and %zu tetrahedra", np, nc);
    for (size_t i = 0; i < 3 * np; i++) {
        out->points[i] = (float)d->pts[i];
        if (isfinite(out->points[i]) && fabs(d->pts[i]) > RT_VOLUME_MAX_COORD) /* non-finite: tet_validate */
            return errf(s, VFX_ERR_INVALID_ARGUMENT, "point %zu coordinate %c = %g is beyond +-%g "
                        "(RT_VOLUME_MAX_COORD): so far a point makes every cell degenerate next to the "
                        "mesh's extent", i / 3, "xyz"[i % 3], d->pts[i], RT_VOLUME_MAX_COORD);
    }
    for (size_t i = 0; i < 4 * nc; i++) {
        double v = d->cells[i];
        if (!(v >= 0 && v < (double)np))
            return errf(s, VFX_ERR_FORMAT, "cell %zu vertex %zu: index %g out of range (%zu points)",
                        i / 4, i % 4, v, np);
        if (v != floor(v)) /* a Float connectivity array */
            return errf(s, VFX_ERR_FORMAT, "DataArray 'connectivity': value %zu (cell %zu vertex %zu) "
                        "index %.17g is not an integer", i, i / 4, i % 4, v);
        out->tets[i] = (uint32_t)v;
    }
    if (as) {
        snprintf(out->scalar_name, sizeof out->scalar_name, "%s%.60s%s", as->ncomp > 1 ? "|" : "",
                 as->name, as->ncomp > 1 ? "|" : "");
        size_t k = (size_t)as->ncomp;
        for (size_t i = 0; i < np; i++) {
            double m = 0;
            for (size_t j = 0; j < k; j++)
                m += d->sc[i * k + j] * d->sc[i * k + j];
            out->scalar[i] = (float)(k == 1 ? d->sc[i] : sqrt(m));
        }
    }
    return rt_result_from_tet(tet_validate(out, s->err, s->errlen));
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
    if (!s) {
        snprintf(err, errlen, "out of memory for the parser state");
        return VFX_ERR_OUT_OF_MEMORY;
    }
    s->data = data;
    s->size = size;
    s->cur = -1;
    s->err = err;
    s->errlen = errlen;
    vtu_decoded d = {0};
    vfx_result r = vtu_parse(s, &d);
    if (!r) r = vtu_find_arrays(s, scalar_name, &d);
    if (!r) r = read_array(s, d.points, (size_t)s->npoints, &d.pts, d.app_start);
    if (!r) r = vtu_read_cells(s, &d);
    if (!r && d.scalar) r = read_array(s, d.scalar, (size_t)s->npoints, &d.sc, d.app_start);
    if (!r) r = vtu_assemble(s, &d, out);
    if (r != VFX_OK) tet_mesh_free(out);
    if (s->parser) XML_ParserFree(s->parser);
    free(s);
    free(d.pts); free(d.cells); free(d.sc);
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
    char *buf;
    size_t n;
    vfx_result rr = rt_read_file(path, RT_VOLUME_MAX_FILE_BYTES,
                                 "1 GiB for a volume file (RT_VOLUME_MAX_FILE_BYTES)", &buf, &n, err, errlen);
    if (rr)
        return rr;
    char inner[512] = "";
    vfx_result r = rt_volume_load_vtu_mem(buf, n, scalar_name, out, inner, sizeof inner);
    if (r != VFX_OK)
        snprintf(err, errlen, "%s: %s", path, inner);
    free(buf);
    return r;
}
