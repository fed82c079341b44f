/* shader_text.c — GLSL text handling shared by the plugin and the host: #include expansion
 * with #line numbering, hot-reload override, and driver log rewriting to file:line. */
#include "shader_text.h"

#include <ctype.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------------- shader text */

int volfx_shader_index(const volfx_shader_table *t, const char *path)
{
    for (unsigned i = 0; i < t->count; ++i)
        if (strcmp(t->entries[i].path, path) == 0)
            return (int)i;
    return -1;
}

/* Development hot reload: a readable file under VFX_SHADER_DIR wins over the embedded copy. */
static char *load_override(const char *path)
{
#ifdef VFX_SHADER_DIR
    char full[512];
    snprintf(full, sizeof full, "%s/%s", VFX_SHADER_DIR, path);
    FILE *f = fopen(full, "rb");
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (buf && fread(buf, 1, (size_t)n, f) == (size_t)n) {
        buf[n] = 0;
    } else {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    return buf;
#else
    (void)path;
    return NULL;
#endif
}

typedef struct strbuf {
    char *p;
    size_t len, cap;
    bool oom;
} strbuf;

static void sb_put(strbuf *b, const char *s, size_t n)
{
    if (b->oom)
        return;
    if (b->len + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->len + n + 1)
            cap *= 2;
        char *p = realloc(b->p, cap);
        if (!p) {
            b->oom = true;
            return;
        }
        b->p = p;
        b->cap = cap;
    }
    memcpy(b->p + b->len, s, n);
    b->len += n;
    b->p[b->len] = 0;
}

static void sb_printf(strbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void sb_printf(strbuf *b, const char *fmt, ...)
{
    char tmp[512];
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(tmp, sizeof tmp, fmt, ap);
    va_end(ap);
    if (n > 0)
        sb_put(b, tmp, (size_t)n < sizeof tmp ? (size_t)n : sizeof tmp - 1);
}

long volfx_shader_line_base(int index) { return (long)(index + 1) * VOLFX_SHADER_LINE_STRIDE; }

/* Expands one level of #include "x" with #line directives so the driver's line numbers point
 * into the right file: source-string number = the file's index in the embedded table. */
static bool expand(strbuf *out, const volfx_shader_table *t, const char *path, const char *defines, int depth,
                   char *err, size_t errlen)
{
    int idx = volfx_shader_index(t, path);
    char *override = load_override(path);
    const char *src = override ? override : (idx >= 0 ? t->entries[idx].source : NULL);
    if (!src) {
        snprintf(err, errlen, "shader '%s' is not embedded (listed in shaders/*/meson.build?)", path);
        return false;
    }
    if (depth == 0) {
        sb_printf(out, "#version 450 core\n");
        if (defines)
            sb_printf(out, "%s\n", defines);
    }
    sb_printf(out, "#line %ld\n", volfx_shader_line_base(idx) + 1);
    int line = 1;
    for (const char *p = src; *p;) {
        const char *e = strchr(p, '\n');
        size_t n = e ? (size_t)(e - p) : strlen(p);
        const char *q = p;
        while (q < p + n && isspace((unsigned char)*q))
            ++q;
        if (depth == 0 && strncmp(q, "#version", 8) == 0) {
            /* we put our own #version first */
        } else if (strncmp(q, "#include", 8) == 0) {
            const char *a = strchr(q, '"'), *b = a ? strchr(a + 1, '"') : NULL;
            if (!a || !b || b > p + n || depth > 0) {
                snprintf(err, errlen, "%s:%d: bad or nested #include", path, line);
                free(override);
                return false;
            }
            char inc[128];
            snprintf(inc, sizeof inc, "%.*s", (int)(b - a - 1), a + 1);
            if (!expand(out, t, inc, NULL, depth + 1, err, errlen)) {
                free(override);
                return false;
            }
            sb_printf(out, "\n#line %ld\n", volfx_shader_line_base(idx) + line + 1);
        } else {
            sb_put(out, p, n);
            sb_put(out, "\n", 1);
        }
        p += n + (e ? 1 : 0);
        ++line;
    }
    free(override);
    return !out->oom;
}

/* Rewrites "N:L(C): msg" (Mesa) and "N(L) : msg" (NVIDIA) into "file:L: msg". */
void volfx_shader_rewrite_log(const volfx_shader_table *t, const char *log, char *out, size_t cap,
                              const char *fallback)
{
    size_t o = 0;
    for (const char *p = log; *p && o + 1 < cap;) {
        const char *e = strchr(p, '\n');
        size_t n = e ? (size_t)(e - p) : strlen(p);
        char *end;
        long file = strtol(p, &end, 10);
        long line = -1;
        const char *rest = p;
        if (end != p && (*end == ':' || *end == '(')) {
            char *end2;
            line = strtol(end + 1, &end2, 10);
            if (end2 != end + 1) {
                rest = end2;
                while (*rest == ')' || *rest == '(' || isdigit((unsigned char)*rest) || *rest == ' ' || *rest == ':')
                    ++rest;
            } else {
                line = -1;
            }
        }
        if (line >= VOLFX_SHADER_LINE_STRIDE) { /* the file is encoded in the line number */
            file = line / VOLFX_SHADER_LINE_STRIDE - 1;
            line %= VOLFX_SHADER_LINE_STRIDE;
        }
        const char *name = (line >= 0 && file >= 0 && file < (long)t->count) ? t->entries[file].path : fallback;
        int w;
        if (line >= 0)
            w = snprintf(out + o, cap - o, "%s:%ld: %.*s\n", name, line, (int)(n - (size_t)(rest - p)), rest);
        else
            w = snprintf(out + o, cap - o, "%s: %.*s\n", fallback, (int)n, p);
        if (w < 0)
            break;
        o += (size_t)w < cap - o ? (size_t)w : cap - o - 1;
        p += n + (e ? 1 : 0);
    }
    out[o < cap ? o : cap - 1] = 0;
}

char *volfx_shader_expand(const volfx_shader_table *t, const char *path, const char *defines, char *err,
                          size_t errlen)
{
    strbuf b = {0};
    if (!expand(&b, t, path, defines, 0, err, errlen) || b.oom) {
        if (b.oom)
            snprintf(err, errlen, "out of memory expanding shader '%s'", path);
        free(b.p);
        return NULL;
    }
    return b.p;
}
