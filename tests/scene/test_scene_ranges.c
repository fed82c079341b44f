/* Documented ranges against the loader: walks the key table of docs/scene-format.md (the path is
 * argv[1]), reads each numeric key's documented range ("(0, 179]", "1..16384", "dt in (0, 0.1]",
 * "ramp_s in [0, 1e4]", "> 0", ...), and loads a minimal scene with the key at each end (must
 * load) and just outside (must be refused with VFX_ERR_INVALID_ARGUMENT, naming the key's JSON
 * path). A documented end the loader refuses, or a value past it that loads, fails the test
 * ("documented means working": paddle.ramp_s 0 was documented and refused). Rows whose range is
 * prose or whose key is not a plain number are listed and skipped; the test also fails when
 * fewer keys than expected were understood, so a change of the table's wording cannot make it
 * test nothing. */
#include <cjson/cJSON.h>
#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"

typedef struct interval {
    bool has_lo, has_hi, lo_open, hi_open, integer;
    double lo, hi;
} interval;

static int failures, tested_keys, tested_values;

static void trim(char *s)
{
    size_t n = strlen(s);
    while (n && isspace((unsigned char)s[n - 1]))
        s[--n] = 0;
    size_t k = 0;
    while (s[k] && isspace((unsigned char)s[k]))
        ++k;
    memmove(s, s + k, strlen(s + k) + 1);
}

/* Splits a table row at '|' (not at "\|"); returns the number of cells. */
static int split_row(char *line, char cells[][1024], int max)
{
    int n = 0;
    size_t k = 0;
    char *p = line;
    if (*p == '|')
        ++p;
    for (; *p && n < max; ++p) {
        if (*p == '\\' && p[1] == '|') {
            if (k < 1023)
                cells[n][k++] = '|';
            ++p;
            continue;
        }
        if (*p == '|' || *p == '\n') {
            cells[n][k] = 0;
            trim(cells[n]);
            ++n, k = 0;
            if (*p == '\n')
                break;
            continue;
        }
        if (k < 1023)
            cells[n][k++] = *p;
    }
    return n;
}

/* An interval at the start of s: "(a, b]", "[a,b]", "a..b", ">= a", "> a". */
static bool parse_interval(const char *s, interval *iv)
{
    *iv = (interval){0};
    char *e;
    while (isspace((unsigned char)*s))
        ++s;
    if (*s == '(' || *s == '[') {
        iv->lo_open = *s == '(';
        iv->lo = strtod(s + 1, &e);
        if (e == s + 1)
            return false;
        while (isspace((unsigned char)*e))
            ++e;
        if (*e != ',')
            return false;
        const char *h = e + 1;
        iv->hi = strtod(h, &e);
        if (e == h)
            return false;
        while (isspace((unsigned char)*e))
            ++e;
        if (*e != ']' && *e != ')')
            return false;
        iv->hi_open = *e == ')';
        iv->has_lo = iv->has_hi = true;
        return true;
    }
    if (*s == '>') {
        iv->lo_open = s[1] != '=';
        const char *v = s + (iv->lo_open ? 1 : 2);
        iv->lo = strtod(v, &e);
        if (e == v)
            return false;
        iv->has_lo = true;
        return true;
    }
    /* "a..b": strtod would read "1." of "1..8" */
    const char *dd = strstr(s, "..");
    if (!dd || dd == s || dd - s > 30)
        return false;
    char lo[32];
    snprintf(lo, sizeof lo, "%.*s", (int)(dd - s), s);
    iv->lo = strtod(lo, &e);
    if (e == lo || *e)
        return false;
    const char *h = dd + 2;
    iv->hi = strtod(h, &e);
    if (e == h)
        return false;
    iv->has_lo = iv->has_hi = true;
    iv->integer = iv->lo == floor(iv->lo) && iv->hi == floor(iv->hi);
    return true;
}

/* Splits s at the commas outside brackets; returns the count. */
static int split_top(const char *s, char out[][256], int max)
{
    int n = 0, depth = 0;
    size_t k = 0;
    for (; *s && n < max; ++s) {
        if (*s == '(' || *s == '[')
            depth++;
        if (*s == ')' || *s == ']')
            depth--;
        if (*s == ',' && depth == 0) {
            out[n][k] = 0, trim(out[n]), ++n, k = 0;
            continue;
        }
        if (k < 255)
            out[n][k++] = *s;
    }
    if (n < max)
        out[n][k] = 0, trim(out[n]), ++n;
    return n;
}

/* The minimal scene for a key under `prefix` (dotted, "beams[i]" for an element), as a cJSON
 * tree; *obj gets the object the key goes in. */
static cJSON *base_scene(const char *prefix, cJSON **obj)
{
    const char *text = NULL;
    if (!strncmp(prefix, "water.simulation", 16))
        text = "{\"water\":{\"source\":\"simulation\",\"simulation\":{\"tank\":{\"min\":[0,0,0],\"max\":[1,1,1]},"
               "\"fluid\":{\"min\":[0,0,0],\"max\":[1,0.5,1]},\"particle_count\":10}}}";
    else if (!strncmp(prefix, "water.generator", 15))
        text = "{\"water\":{\"source\":\"generator\",\"generator\":{\"kind\":\"layers\",\"count\":10}}}";
    else if (!strncmp(prefix, "water", 5))
        text = "{\"water\":{\"source\":\"file\",\"path\":\"p\"}}";
    else if (!strncmp(prefix, "beams[i]", 8))
        text = "{\"beams\":[{\"head\":[0,0,0],\"dir\":[1,0,0]}]}";
    else if (!strncmp(prefix, "volume", 6))
        text = "{\"volume\":{\"path\":\"a.vtu\"}}";
    else
        text = "{}";
    cJSON *root = cJSON_Parse(text);
    cJSON *o = root;
    char buf[256];
    snprintf(buf, sizeof buf, "%s", prefix);
    for (char *seg = strtok(buf, "."); seg; seg = strtok(NULL, ".")) {
        if (!strcmp(seg, "beams[i]")) {
            o = cJSON_GetArrayItem(cJSON_GetObjectItem(o, "beams"), 0);
            continue;
        }
        cJSON *next = cJSON_GetObjectItem(o, seg);
        if (!next)
            next = cJSON_AddObjectToObject(o, seg);
        o = next;
    }
    *obj = o;
    return root;
}

/* Loads the scene with prefix.key = v; expect_ok or a refusal naming the key's path. */
static void try_value(const char *prefix, const char *key, double v, bool expect_ok)
{
    cJSON *obj, *root = base_scene(prefix, &obj);
    cJSON_DeleteItemFromObject(obj, key);
    cJSON_AddNumberToObject(obj, key, v);
    char *json = cJSON_PrintUnformatted(root);
    rt_scene *s = NULL;
    char err[512] = "", path[256], *q;
    rt_logger quiet = {NULL, NULL};
    (void)quiet;
    snprintf(path, sizeof path, "%s.%s", prefix, key);
    while ((q = strstr(path, "[i]")))
        q[1] = '0';
    vfx_result r = rt_scene_load_mem(json, strlen(json), "/base", NULL, &s, err, sizeof err);
    bool ok = expect_ok ? r == VFX_OK : (r == VFX_ERR_INVALID_ARGUMENT && strstr(err, path) != NULL);
    if (!ok) {
        failures++;
        printf("FAIL %s = %.9g: expected %s, got %d \"%s\"\n", path, v, expect_ok ? "accepted" : "refused naming it",
               (int)r, err);
    }
    tested_values++;
    rt_scene_free(s);
    cJSON_free(json);
    cJSON_Delete(root);
}

/* Just past x, outward (dir -1 below, +1 above), as float32 keeps it. */
static double past(double x, int dir, bool integer)
{
    if (integer)
        return x + dir;
    double d = fmax(fabs(x) * 1e-5, 1e-6);
    return x + dir * d;
}

static void test_key(const char *prefix, const char *key, const interval *iv)
{
    tested_keys++;
    if (iv->has_lo) {
        if (iv->lo_open) {
            try_value(prefix, key, iv->lo, false);
            try_value(prefix, key, past(iv->lo, +1, iv->integer), true);
        } else {
            try_value(prefix, key, iv->lo, true);
            try_value(prefix, key, past(iv->lo, -1, iv->integer), false);
        }
    }
    if (iv->has_hi) {
        if (iv->hi_open) {
            try_value(prefix, key, iv->hi, false);
        } else {
            try_value(prefix, key, iv->hi, true);
            try_value(prefix, key, past(iv->hi, +1, iv->integer), false);
        }
    }
}

/* Keys whose documented range is a plain number range in the key column's own words but which
 * another key bounds as well (tested elsewhere): far > near, step within [h/1024, h]. */
static bool coupled(const char *prefix, const char *key)
{
    return !strcmp(prefix, "camera") && !strcmp(key, "far");
}

static void walk_row(char cells[][1024], int n)
{
    if (n < 4 || strchr(cells[0], '{') || strstr(cells[0], " or ") || strchr(cells[0], '/'))
        return;
    char keycol[1024];
    memcpy(keycol, cells[0], sizeof keycol);
    char *par = strchr(keycol, '(');
    if (par)
        *par = 0;
    char names[16][256], types[16][256], ranges[16][256];
    int nn = split_top(keycol, names, 16), nt = split_top(cells[1], types, 16), nr = split_top(cells[3], ranges, 16);
    char *dot = strrchr(names[0], '.');
    if (!dot)
        return;
    char prefix[256];
    snprintf(prefix, sizeof prefix, "%.*s", (int)(dot - names[0]), names[0]);
    memmove(names[0], dot + 1, strlen(dot + 1) + 1);
    int numeric = 0;
    for (int k = 0; k < nn; ++k) {
        const char *type = nt == nn ? types[k] : nt == 1 ? types[0] : "";
        numeric += !strcmp(type, "number") || !strcmp(type, "int");
    }
    for (int k = 0; k < nn; ++k) {
        const char *type = nt == nn ? types[k] : nt == 1 ? types[0] : "";
        if (strcmp(type, "number") != 0 && strcmp(type, "int") != 0)
            continue;
        interval iv;
        bool found = false;
        /* "NAME <interval>", "NAME in <interval>" or "NAME (prose) in <interval>" anywhere in the
         * range cell; NAME also as its part after the first '_' (bloom_levels: "levels 1..8") */
        const char *under = strchr(names[k], '_');
        const char *alias[3] = {names[k], under ? under + 1 : NULL, "others"};
        for (int a = 0; a < 3 && !found; ++a) {
            if (!alias[a])
                continue;
            size_t al = strlen(alias[a]);
            for (const char *p = strstr(cells[3], alias[a]); p && !found; p = strstr(p + 1, alias[a])) {
                if ((p != cells[3] && (isalnum((unsigned char)p[-1]) || p[-1] == '_')) || p[al] != ' ')
                    continue;
                const char *q = p + al + 1;
                if (*q == '(' && strchr(q, ')'))
                    q = strchr(q, ')') + 1;
                while (*q == ' ')
                    ++q;
                if (!strncmp(q, "in ", 3))
                    q += 3;
                found = parse_interval(q, &iv);
            }
        }
        /* the row's one interval for its numeric keys: the cell starts with it */
        if (!found && (numeric == 1 || nr == 1))
            found = parse_interval(cells[3], &iv);
        /* one interval per key, in order */
        if (!found && nr == nn && nn > 1)
            found = parse_interval(ranges[k], &iv);
        if (!found) {
            printf("skipped %s.%s: range \"%.60s\" not a plain interval\n", prefix, names[k], cells[3]);
            continue;
        }
        if (coupled(prefix, names[k])) {
            printf("skipped %s.%s: bounded by another key as well\n", prefix, names[k]);
            continue;
        }
        if (!strcmp(type, "int"))
            iv.integer = true;
        printf("%s.%s: %s%g, %g%s\n", prefix, names[k], iv.lo_open ? "(" : "[", iv.has_lo ? iv.lo : -INFINITY,
               iv.has_hi ? iv.hi : INFINITY, iv.hi_open ? ")" : "]");
        test_key(prefix, names[k], &iv);
    }
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: test_scene_ranges docs/scene-format.md\n");
        return 2;
    }
    FILE *f = fopen(argv[1], "r");
    if (!f) {
        fprintf(stderr, "cannot open %s\n", argv[1]);
        return 2;
    }
    static char line[8192];
    static char cells[8][1024];
    bool in_table = false;
    while (fgets(line, sizeof line, f)) {
        if (!strncmp(line, "| key | type | default | range |", 32)) {
            in_table = true;
            continue;
        }
        if (!in_table)
            continue;
        if (line[0] != '|')
            break;
        if (!strncmp(line, "|---", 4))
            continue;
        walk_row(cells, split_row(line, cells, 8));
    }
    fclose(f);
    printf("%d keys, %d values tried, %d failures\n", tested_keys, tested_values, failures);
    /* 35 keys were understood when this test was written: fewer means the table's wording
     * changed under the parser, not that the ranges are right */
    if (tested_keys < 30) {
        printf("FAIL only %d keys understood (expected at least 30)\n", tested_keys);
        return 1;
    }
    return failures ? 1 : 0;
}
