/* test_tet_io.c — loaders: good files in each encoding, the real pipe mesh, and each malformed
 * input giving a specific code and a message naming what went wrong. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "scene/volume_file.h"

/* One tet, positively oriented, plus a second one written inverted. */
#define HEAD "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" " \
             "byte_order=\"LittleEndian\" header_type=\"UInt32\"%s>\n<UnstructuredGrid>\n" \
             "<Piece NumberOfPoints=\"%s\" NumberOfCells=\"2\">\n"
static const char *ascii_body =
    "<PointData><DataArray type=\"Float64\" Name=\"V\" NumberOfComponents=\"3\" format=\"ascii\">"
    "3 4 0  0 0 1  1 0 0  0 2 0  0 0 0</DataArray>"
    "<DataArray type=\"Float32\" Name=\"P\" format=\"ascii\">1 2 3 4 %s</DataArray></PointData>\n"
    "<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">"
    "0 0 0 1 0 0 0 1 0 0 0 1 %s</DataArray></Points>\n"
    "<Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">0 1 2 3 0 2 1 %s"
    "</DataArray>\n<DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">4 8</DataArray>\n"
    "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">10 %s</DataArray></Cells>\n"
    "</Piece></UnstructuredGrid></VTKFile>\n";

static char *make_ascii(const char *npts, const char *p5, const char *x5, const char *last,
                        const char *type2)
{
    static char buf[4096];
    int n = snprintf(buf, sizeof buf, HEAD, "", npts);
    snprintf(buf + n, sizeof buf - (size_t)n, ascii_body, p5, x5, last, type2);
    return buf;
}

static vfx_result load_str(const char *s, const char *field, tet_mesh *m, char *err)
{
    return rt_volume_load_vtu_mem(s, strlen(s), field, m, err, 256);
}

static void test_ascii_good(void **st)
{
    (void)st;
    tet_mesh m;
    char err[256];
    assert_int_equal(load_str(make_ascii("5", "5", "2 2 2", "4", "10"), "V", &m, err), VFX_OK);
    assert_int_equal(m.point_count, 5);
    assert_int_equal(m.tet_count, 2);
    assert_int_equal(m.inverted_fixed, 1); /* second tet 0,2,1,4 has negative volume */
    assert_int_equal(m.degenerate_count, 0);
    assert_float_equal(m.scalar[0], 5.0f, 1e-6f); /* |(3,4,0)| */
    assert_float_equal(m.scalar_max, 5.0f, 1e-6f);
    assert_float_equal(m.scalar_min, 0.0f, 0.0f);
    assert_string_equal(m.scalar_name, "|V|");
    tet_mesh_free(&m);
}

static void test_missing_field(void **st)
{
    (void)st;
    tet_mesh m;
    char err[256];
    assert_int_equal(load_str(make_ascii("5", "5", "2 2 2", "4", "10"), "Pressure", &m, err),
                     VFX_ERR_NOT_FOUND);
    assert_non_null(strstr(err, "'Pressure' not found"));
    assert_non_null(strstr(err, "V P"));
    assert_null(m.points);
}

static void test_non_tet(void **st)
{
    (void)st;
    tet_mesh m;
    char err[256];
    assert_int_equal(load_str(make_ascii("5", "5", "2 2 2", "4", "12"), NULL, &m, err),
                     VFX_ERR_UNSUPPORTED);
    assert_non_null(strstr(err, "cell 1 has VTK type 12"));
}

static void test_index_out_of_range(void **st)
{
    (void)st;
    tet_mesh m;
    char err[256];
    assert_int_equal(load_str(make_ascii("5", "5", "2 2 2", "7", "10"), NULL, &m, err),
                     VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "cell 1 vertex 3: index 7 out of range"));
}

static void test_nan_coordinate(void **st)
{
    (void)st;
    tet_mesh m;
    char err[256];
    assert_int_equal(load_str(make_ascii("5", "5", "2 nan 2", "4", "10"), NULL, &m, err),
                     VFX_ERR_NUMERIC);
    assert_non_null(strstr(err, "point 4"));
}

static void test_nan_scalar(void **st)
{
    (void)st;
    tet_mesh m;
    char err[256];
    assert_int_equal(load_str(make_ascii("5", "nan", "2 2 2", "4", "10"), "P", &m, err),
                     VFX_ERR_NUMERIC);
    assert_non_null(strstr(err, "scalar 'P' is not finite at point 4"));
}

static void test_wrong_counts(void **st)
{
    (void)st;
    tet_mesh m;
    char err[256];
    /* 6 points declared, 5 given */
    assert_int_equal(load_str(make_ascii("6", "5", "2 2 2", "4", "10"), NULL, &m, err),
                     VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "too few values"));
    assert_int_equal(load_str(make_ascii("0", "5", "2 2 2", "4", "10"), NULL, &m, err),
                     VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "NumberOfPoints"));
}

static void test_empty_and_not_xml(void **st)
{
    (void)st;
    tet_mesh m;
    char err[256];
    assert_int_equal(rt_volume_load_vtu_mem("", 0, NULL, &m, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "empty"));
    assert_int_equal(load_str("solid cube\nfacet normal 0 0 1\n", NULL, &m, err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "not valid XML"));
    const char *s = make_ascii("5", "5", "2 2 2", "4", "10");
    assert_int_equal(rt_volume_load_vtu_mem(s, strlen(s) / 2, NULL, &m, err, sizeof err),
                     VFX_ERR_FORMAT); /* truncated */
    assert_non_null(strstr(err, "not valid XML"));
    assert_int_equal(rt_volume_load_vtu("/nonexistent/x.vtu", NULL, &m, err, sizeof err),
                     VFX_ERR_IO);
}

/* Binary encodings built here with zlib so that fixtures stay tiny and self-describing. */
static const float pts5[15] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 2, 2, 2};
static const int64_t conn8[8] = {0, 1, 2, 3, 0, 2, 1, 4};
static const int32_t offs2[2] = {4, 8};
static const uint8_t types2[2] = {10, 10};
static const double p5[5] = {1, 2, 3, 4, 5};

static size_t b64(const unsigned char *in, size_t n, char *out)
{
    static const char *T = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    size_t o = 0;
    for (size_t i = 0; i < n; i += 3) {
        unsigned v = (unsigned)in[i] << 16 | (i + 1 < n ? (unsigned)in[i + 1] << 8 : 0) |
                     (i + 2 < n ? in[i + 2] : 0);
        out[o++] = T[v >> 18 & 63];
        out[o++] = T[v >> 12 & 63];
        out[o++] = i + 1 < n ? T[v >> 6 & 63] : '=';
        out[o++] = i + 2 < n ? T[v & 63] : '=';
    }
    out[o] = 0;
    return o;
}

/* Encodes one array as VTK does: [UInt32 len] + data, or zlib [1, n, n, csize] + block. */
static size_t encode(const void *data, size_t n, int zlib, unsigned char *out)
{
    if (!zlib) {
        uint32_t h = (uint32_t)n;
        memcpy(out, &h, 4);
        memcpy(out + 4, data, n);
        return 4 + n;
    }
    uLongf cl = 256;
    unsigned char c[256];
    compress(c, &cl, data, n);
    uint32_t h[4] = {1, (uint32_t)n, (uint32_t)n, (uint32_t)cl};
    memcpy(out, h, 16);
    memcpy(out + 16, c, cl);
    return 16 + cl;
}

enum { ENC_BINARY, ENC_RAW, ENC_APP64 };
static size_t build_binary(char *buf, size_t cap, int enc, int zlib, int corrupt)
{
    const void *arr[5] = {pts5, conn8, offs2, types2, p5};
    size_t sz[5] = {sizeof pts5, sizeof conn8, sizeof offs2, sizeof types2, sizeof p5};
    const char *decl[5] = {"<Points><DataArray type=\"Float32\" NumberOfComponents=\"3\"",
                           "<Cells><DataArray type=\"Int64\" Name=\"connectivity\"",
                           "<DataArray type=\"Int32\" Name=\"offsets\"",
                           "<DataArray type=\"UInt8\" Name=\"types\"",
                           "<PointData><DataArray type=\"Float64\" Name=\"P\""};
    const char *close[5] = {"</DataArray></Points>\n", "</DataArray>\n", "</DataArray>\n",
                            "</DataArray></Cells>\n", "</DataArray></PointData>\n"};
    unsigned char app[2048];
    size_t napp = 0;
    size_t n = (size_t)snprintf(buf, cap, HEAD, zlib ? " compressor=\"vtkZLibDataCompressor\"" : "",
                                "5");
    for (int i = 0; i < 5; i++) {
        unsigned char e[512];
        size_t en = encode(arr[i], sz[i], zlib, e);
        if (corrupt == 2 && i == 1 && zlib)
            e[16 + 3] ^= 0x55; /* damage the deflate stream */
        if (enc == ENC_BINARY) {
            char t[1024];
            b64(e, en, t);
            if (corrupt == 1 && i == 1)
                t[5] = '!';
            n += (size_t)snprintf(buf + n, cap - n, "%s format=\"binary\">%s%s", decl[i], t,
                                  close[i]);
        } else {
            n += (size_t)snprintf(buf + n, cap - n, "%s format=\"appended\" offset=\"%zu\">%s",
                                  decl[i], napp, close[i]);
            if (enc == ENC_RAW) {
                memcpy(app + napp, e, en);
                napp += en;
            } else {
                napp += b64(e, en, (char *)app + napp);
                if (corrupt == 1 && i == 1)
                    app[napp - 6] = '!';
            }
        }
    }
    n += (size_t)snprintf(buf + n, cap - n, "</Piece></UnstructuredGrid>\n");
    if (enc != ENC_BINARY) {
        n += (size_t)snprintf(buf + n, cap - n, "<AppendedData encoding=\"%s\">\n_",
                              enc == ENC_RAW ? "raw" : "base64");
        memcpy(buf + n, app, napp);
        n += napp;
        n += (size_t)snprintf(buf + n, cap - n, "\n</AppendedData>\n");
    }
    n += (size_t)snprintf(buf + n, cap - n, "</VTKFile>\n");
    return n;
}

static void test_binary_encodings(void **st)
{
    (void)st;
    char buf[8192];
    for (int enc = 0; enc < 3; enc++)
        for (int z = 0; z < 2; z++) {
            size_t n = build_binary(buf, sizeof buf, enc, z, 0);
            tet_mesh m;
            char err[256];
            vfx_result r = rt_volume_load_vtu_mem(buf, n, "P", &m, err, sizeof err);
            if (r != VFX_OK)
                fail_msg("enc %d zlib %d: %s", enc, z, err);
            assert_int_equal(m.tet_count, 2);
            assert_int_equal(m.inverted_fixed, 1);
            assert_float_equal(m.points[12], 2.0f, 0.0f);
            assert_float_equal(m.scalar[4], 5.0f, 0.0f);
            assert_int_equal(m.tets[6], 4); /* flipped: q2<->q3 */
            tet_mesh_free(&m);
            if (enc != ENC_RAW) {
                n = build_binary(buf, sizeof buf, enc, z, 1);
                assert_int_equal(rt_volume_load_vtu_mem(buf, n, "P", &m, err, sizeof err),
                                 VFX_ERR_FORMAT);
                assert_non_null(strstr(err, "connectivity"));
            }
            if (z) {
                n = build_binary(buf, sizeof buf, enc, z, 2);
                assert_int_equal(rt_volume_load_vtu_mem(buf, n, "P", &m, err, sizeof err),
                                 VFX_ERR_FORMAT);
                assert_non_null(strstr(err, "zlib block 0"));
            }
            if (enc == ENC_RAW) { /* truncated appended data */
                n = build_binary(buf, sizeof buf, enc, z, 0);
                assert_int_equal(rt_volume_load_vtu_mem(buf, n - 40, "P", &m, err, sizeof err),
                                 VFX_ERR_FORMAT);
            }
        }
}

static void test_pipe(void **st)
{
    (void)st;
    const char *dir = getenv("VFX_SHARED_DATA");
    char path[512];
    snprintf(path, sizeof path, "%s/tets/pipe_RCR_init_flow.vtu", dir ? dir : "../shared/data");
    tet_mesh m;
    char err[256];
    vfx_result r = rt_volume_load_vtu(path, "Velocity", &m, err, sizeof err);
    if (r != VFX_OK)
        fail_msg("%s", err);
    assert_int_equal(m.point_count, 30211);
    assert_int_equal(m.tet_count, 170694);
    assert_int_equal(m.inverted_fixed, 170694); /* README: every tet is inverted */
    assert_int_equal(m.degenerate_count, 0);
    assert_float_equal(m.scalar_min, 0.0f, 1e-3f);
    assert_float_equal(m.scalar_max, 8.19f, 0.01f); /* README gives 8.19 to 2 decimals */
    tet_mesh_free(&m);
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
}

static void test_tetgen(void **st)
{
    (void)st;
    char base[] = "/tmp/vfx_tg_XXXXXX";
    int fd = mkstemp(base);
    assert_true(fd >= 0);
    char p[64];
    tet_mesh m;
    char err[256];
    snprintf(p, sizeof p, "%s.node", base);
    write_file(p, "# comment\n5 3 1 0\n1 0 0 0 1.5\n2 1 0 0 2\n3 0 1 0 3 # c\n4 0 0 1 4\n"
                  "5 2 2 2 5\n");
    snprintf(p, sizeof p, "%s.ele", base);
    write_file(p, "2 4 0\n1 1 2 3 4\n2 1 3 2 5\n");
    assert_int_equal(rt_volume_load_tetgen(base, "attr0", &m, err, sizeof err), VFX_OK);
    assert_int_equal(m.tet_count, 2);
    assert_int_equal(m.tets[6], 4); /* flipped: q2<->q3 */ /* 1-based 5 -> 4 */
    assert_int_equal(m.inverted_fixed, 1);
    assert_float_equal(m.scalar_min, 1.5f, 0.0f);
    tet_mesh_free(&m);
    assert_int_equal(rt_volume_load_tetgen(base, "attr3", &m, err, sizeof err), VFX_ERR_NOT_FOUND);
    assert_non_null(strstr(err, "attr0..attr0"));
    write_file(p, "2 4 0\n1 1 2 3 4\n2 1 3 2 9\n");
    assert_int_equal(rt_volume_load_tetgen(base, NULL, &m, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "tetrahedron 1 vertex 3 index 9 out of range"));
    write_file(p, "3 4 0\n1 1 2 3 4\n2 1 3 2 5\n");
    assert_int_equal(rt_volume_load_tetgen(base, NULL, &m, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "truncated: 2 of 3"));
    write_file(p, "2 4 0\n1 1 2 3 4\n2 1 3 x 5\n");
    assert_int_equal(rt_volume_load_tetgen(base, NULL, &m, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, ":3: tetrahedron 1"));
    write_file(p, "");
    assert_int_equal(rt_volume_load_tetgen(base, NULL, &m, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "missing or bad header"));
    snprintf(p, sizeof p, "%s.node", base);
    write_file(p, "5 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 inf\n4 2 2 2\n");
    snprintf(p, sizeof p, "%s.ele", base);
    write_file(p, "1 4 0\n0 0 1 2 3\n");
    assert_int_equal(rt_volume_load_tetgen(base, NULL, &m, err, sizeof err), VFX_ERR_NUMERIC);
    assert_non_null(strstr(err, "point 3"));
    remove(p);
    snprintf(p, sizeof p, "%s.node", base);
    remove(p);
    remove(base);
}

static char *replace_once(const char *s, const char *from, const char *to)
{
    static char buf[8192];
    const char *at = strstr(s, from);
    assert_non_null(at);
    snprintf(buf, sizeof buf, "%.*s%s%s", (int)(at - s), s, to, at + strlen(from));
    return buf;
}

/* Inputs the other tests leave out: non-4 offsets, a missing Cells array, 2-component points,
 * no Piece, AppendedData without its marker, a coincident-vertex tet (kept and counted as
 * degenerate, not refused), and TetGen with the .ele file missing or a node line too short. */
static void test_more_malformed(void **st)
{
    (void)st;
    tet_mesh m;
    char err[256];
    const char *good = make_ascii("5", "5", "2 2 2", "4", "10");
    char copy[4096];
    snprintf(copy, sizeof copy, "%s", good);
    assert_int_equal(load_str(replace_once(copy, ">4 8<", ">4 9<"), NULL, &m, err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "cell 1: offset 9, expected 8"));
    assert_int_equal(load_str(replace_once(copy, "Name=\"offsets\"", "Name=\"offs\""), NULL, &m, err),
                     VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "missing Cells offsets"));
    assert_int_equal(load_str(replace_once(copy, "Float32\" NumberOfComponents=\"3\"",
                                           "Float32\" NumberOfComponents=\"2\""), NULL, &m, err),
                     VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "Points must be 3-component"));
    char nopiece[4096];
    snprintf(nopiece, sizeof nopiece, "%s", replace_once(copy, "<Piece ", "<Peace "));
    assert_int_equal(load_str(replace_once(nopiece, "</Piece>", "</Peace>"), NULL, &m, err),
                     VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "no UnstructuredGrid Piece"));
    char app[8192];
    size_t n = build_binary(app, sizeof app, ENC_RAW, 0, 0);
    char *mark = strstr(app, "<AppendedData encoding=\"raw\">\n_");
    assert_non_null(mark);
    mark[strlen("<AppendedData encoding=\"raw\">\n")] = 'X';
    assert_int_equal(rt_volume_load_vtu_mem(app, n, "P", &m, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "without its '_' marker"));
    /* point 4 placed on point 0: the second tet (0,2,1,4) has two identical vertices */
    assert_int_equal(load_str(make_ascii("5", "5", "0 0 0", "4", "10"), "P", &m, err), VFX_OK);
    assert_int_equal(m.tet_count, 2);
    assert_int_equal(m.degenerate_count, 1);
    tet_mesh_free(&m);

    char base[] = "/tmp/vfx_tg2_XXXXXX";
    int fd = mkstemp(base);
    assert_true(fd >= 0);
    char p[64];
    snprintf(p, sizeof p, "%s.node", base);
    write_file(p, "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n");
    assert_int_equal(rt_volume_load_tetgen(base, NULL, &m, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, ".ele: cannot open"));
    write_file(p, "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1\n3 0 0 1\n");
    snprintf(p, sizeof p, "%s.ele", base);
    write_file(p, "1 4 0\n0 0 1 2 3\n");
    assert_int_equal(rt_volume_load_tetgen(base, NULL, &m, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, ":4: point 2 has 3 numbers, expected 4"));
    remove(p);
    snprintf(p, sizeof p, "%s.node", base);
    remove(p);
    remove(base);
}

static int pipe_present(void)
{
    const char *dir = getenv("VFX_SHARED_DATA");
    char path[512];
    snprintf(path, sizeof path, "%s/tets/pipe_RCR_init_flow.vtu", dir ? dir : "../shared/data");
    FILE *f = fopen(path, "rb");
    if (f)
        fclose(f);
    return f != NULL;
}

/* "gen": scripts/make-tet-mesh.sh with 2,000 points, then load it (77 without tetgen/python). */
static int run_generated(void)
{
    const char *root = getenv("VFX_SOURCE_ROOT");
    char dir[] = "/tmp/vfx_gen_XXXXXX", cmd[1024], base[128], err[256];
    if (!root || system("command -v tetgen >/dev/null && test -x /usr/bin/python3") != 0)
        return 77;
    if (!mkdtemp(dir))
        return 1;
    snprintf(base, sizeof base, "%s/torus", dir);
    snprintf(cmd, sizeof cmd, "sh '%s/scripts/make-tet-mesh.sh' '%s' 2000 7 >/dev/null", root,
             base);
    int rc = system(cmd);
    tet_mesh m;
    vfx_result r = rc == 0 ? rt_volume_load_tetgen(base, "attr0", &m, err, sizeof err) : VFX_ERR_IO;
    int ok = r == VFX_OK && m.point_count == 2000 && m.tet_count > 5 * 2000 &&
             m.scalar_min >= 0.0f && m.scalar_max <= 2.0f;
    if (r == VFX_OK) {
        printf("generated: %u points, %u tets, %u inverted, %u degenerate, attr0 %g..%g\n",
               m.point_count, m.tet_count, m.inverted_fixed, m.degenerate_count, m.scalar_min,
               m.scalar_max);
        tet_mesh_free(&m);
    } else {
        printf("generated mesh failed: rc %d, %s\n", rc, rc == 0 ? err : "script");
    }
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        return 1;
    return ok ? 0 : 1;
}

/* "pipe" as argv[1] runs only the real-data test: exit 77 (skip) when the file is absent. */
int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "gen"))
        return run_generated();
    if (argc > 1 && !strcmp(argv[1], "pipe")) {
        if (!pipe_present())
            return 77;
        const struct CMUnitTest t[] = {cmocka_unit_test(test_pipe)};
        return cmocka_run_group_tests(t, NULL, NULL);
    }
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ascii_good),        cmocka_unit_test(test_missing_field),
        cmocka_unit_test(test_non_tet),           cmocka_unit_test(test_index_out_of_range),
        cmocka_unit_test(test_nan_coordinate),    cmocka_unit_test(test_nan_scalar),
        cmocka_unit_test(test_wrong_counts),      cmocka_unit_test(test_empty_and_not_xml),
        cmocka_unit_test(test_binary_encodings),  cmocka_unit_test(test_tetgen),
        cmocka_unit_test(test_more_malformed),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
