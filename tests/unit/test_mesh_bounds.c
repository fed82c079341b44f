/* Mesh import bounded before Assimp reads a byte (issue 28): truncated and lying files of every
 * enabled format, generated here, are refused with an error naming the file, fast and in
 * bounded memory; files beside a mesh (an .mtl, a glTF buffer) cannot be FIFOs or devices; the
 * formats the game does not use are refused by name; small valid files of each format import.
 * Before the fix the 189-byte PLY was SIGSEGV, the 22-byte .glb took 4.2 GB and 27 s, the PLY
 * claiming 2e9 vertices all the machine's memory, an .mtl FIFO hung the import. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "gfx/mesh_check.h"
#include "gfx/mesh_import.h"

static void write_file(const char *path, const void *data, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

/* CPU time of this process and of the import processes it has reaped. */
static double cpu_s(void)
{
    double t = 0;
    for (int who = 0; who < 2; ++who) {
        struct rusage ru;
        getrusage(who ? RUSAGE_CHILDREN : RUSAGE_SELF, &ru);
        t += ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
    }
    return t;
}

/* Imports `path`, expects `want` with an error naming the file and holding `needle`, in under
 * half a second of CPU, the import process's included (each case below takes a few ms; the
 * failures took 27 s to minutes). */
static void expect_refused(const char *path, vfx_result want, const char *needle)
{
    rt_mesh_data m;
    char err[600] = "";
    double t0 = cpu_s();
    vfx_result r = rt_mesh_import(path, &m, err, sizeof err);
    double dt = cpu_s() - t0;
    if (r != want || !strstr(err, path) || !strstr(err, needle))
        fail_msg("%s: result %d (want %d), \"%s\" (want \"%s\")", path, r, want, err, needle);
    assert_null(m.positions);
    assert_true(dt < 0.5);
}

static const char ply_head[] = "ply\nformat binary_little_endian 1.0\nelement vertex %s\n"
                               "property float x\nproperty float y\nproperty float z\nelement face %s\n"
                               "property list uchar int vertex_indices\nend_header\n";

/* path imports, with index_count indices */
static void expect_imported(const char *path, uint32_t index_count)
{
    rt_mesh_data m;
    char err[600] = "";
    if (rt_mesh_import(path, &m, err, sizeof err) != VFX_OK)
        fail_msg("%s: %s", path, err);
    assert_int_equal(m.index_count, index_count);
    rt_mesh_data_free(&m);
}

/* A vertex at NaN or 1e39 (Inf as float32): Assimp's FindInvalidData dropped the mesh and the
 * error read "assimp: No meshes remaining" (or, with other meshes, one vanished); refused naming
 * the mesh, the vertex and the coordinate. */
static void test_non_finite_vertices(void **state)
{
    (void)state;
    static const char nan_obj[] = "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n";
    write_file("nan_vertex.obj", nan_obj, sizeof nan_obj - 1);
    expect_refused("nan_vertex.obj", VFX_ERR_FORMAT, "mesh 0 vertex 2 has a non-finite y (nan)");
    static const char inf_obj[] = "v 0 0 0\nv 1e39 0 0\nv 0 1 0\nf 1 2 3\n";
    write_file("inf_vertex.obj", inf_obj, sizeof inf_obj - 1);
    expect_refused("inf_vertex.obj", VFX_ERR_FORMAT, "vertex 1 has a non-finite x (inf)");
    static const char ok_obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    write_file("finite_vertex.obj", ok_obj, sizeof ok_obj - 1);
    expect_imported("finite_vertex.obj", 3);
}

static void test_truncated_binary_ply(void **state)
{
    (void)state;
    /* 8 vertices and 12 faces claimed, cut at 189 bytes: Assimp's post-processing indexed
     * vertices that were never read (SIGSEGV in volfx-game) */
    unsigned char buf[512] = {0};
    int n = snprintf((char *)buf, sizeof buf, ply_head, "8", "12");
    assert_true(n > 0 && n < 189);
    write_file("trunc189.ply", buf, 189);
    expect_refused("trunc189.ply", VFX_ERR_FORMAT, "element vertex claims 8");
}

static void test_ply_claiming_2e9_vertices(void **state)
{
    (void)state;
    unsigned char buf[227] = {0};
    int n = snprintf((char *)buf, sizeof buf, ply_head, "2000000000", "1");
    assert_true(n > 0 && n < 227);
    write_file("huge_count.ply", buf, sizeof buf);
    expect_refused("huge_count.ply", VFX_ERR_FORMAT, "claims 2000000000");
    /* under the cap but more than the body holds, binary and ASCII */
    n = snprintf((char *)buf, sizeof buf, ply_head, "1000", "0");
    write_file("short.ply", buf, sizeof buf);
    expect_refused("short.ply", VFX_ERR_FORMAT, "needs at least 12000 bytes");
    static const char ascii[] = "ply\nformat ascii 1.0\nelement vertex 100\nproperty float x\n"
                                "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n";
    write_file("short_ascii.ply", ascii, sizeof ascii - 1);
    expect_refused("short_ascii.ply", VFX_ERR_FORMAT, "of ASCII data");
    /* an element with no property takes no byte: its count alone is capped */
    static const char empty_el[] = "ply\nformat ascii 1.0\nelement junk 4000000\nend_header\n";
    write_file("noprop.ply", empty_el, sizeof empty_el - 1);
    expect_refused("noprop.ply", VFX_ERR_FORMAT, "has no property");
    /* list counts live in the body: Assimp sized a face by its count before reading it (an
     * ASCII face of 4e9 indices asked for 32 GB) */
    static const char list_ascii[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                     "property float y\nproperty float z\nelement face 1\n"
                                     "property list uint int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                                     "4000000000 0 1 2\n";
    write_file("list_ascii.ply", list_ascii, sizeof list_ascii - 1);
    expect_refused("list_ascii.ply", VFX_ERR_FORMAT, "a list of 4000000000 items, more than the line holds");
    n = snprintf((char *)buf, sizeof buf, ply_head, "0", "1");
    memset(buf + n, 0xff, 1); /* uchar count 255, no index after it */
    write_file("list_bin.ply", buf, (size_t)n + 1);
    expect_refused("list_bin.ply", VFX_ERR_FORMAT, "a list of 255 items, more than the file holds");
    /* an element declared twice corrupted Assimp's heap (found by fuzz_mesh_ply) */
    static const char twice[] = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement vertex 1\n"
                                "property float x\nend_header\n0\n0\n";
    write_file("twice.ply", twice, sizeof twice - 1);
    expect_refused("twice.ply", VFX_ERR_FORMAT, "element vertex declared twice");
    /* Assimp took the digits of an unknown element name as its count: "88...8vertex" asked for
     * 2.9 GB (found by fuzz_mesh_ply) */
    static const char digits[] = "ply\nformat ascii 1.0\nelement 8888888888888888vertex 3\nproperty float x\n"
                                 "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    write_file("digits.ply", digits, sizeof digits - 1);
    expect_refused("digits.ply", VFX_ERR_FORMAT, "line 3: element name \"8888888888888888vertex\" does not start with a letter");
    /* Assimp ends a line at a lone CR too: its fourth line, the face, claims 4e9 items (32 GB),
     * where a reader splitting at LF sees a vertex x of 4e9 (found by fuzz_mesh_ply) */
    static const char cr[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nelement face 1\n"
                             "property list uchar int vertex_indices\nend_header\n0\r1\n2\n4000000000 0 1 2\n3 0 1 2\n";
    write_file("cr.ply", cr, sizeof cr - 1);
    expect_refused("cr.ply", VFX_ERR_FORMAT, "PLY body line 1: byte 0x0d is not ASCII text (a lone CR");
    /* a line that starts at a CR makes Assimp look for the next LF, past its buffer if none */
    static const char nolf[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nelement face 1\n"
                               "property list uchar int vertex_indices\nend_header\n0\n1\n2\n\r\r3 0 1 2";
    write_file("nolf.ply", nolf, sizeof nolf - 1);
    expect_refused("nolf.ply", VFX_ERR_FORMAT, "PLY body line 4: byte 0x0d is not ASCII text");
    /* Assimp reads an element it does not know as empty: the face's uint count came from the
     * unknown element's float (0xffffffff items, 32 GB asked; found by fuzz_mesh_ply in CI) */
    static const char unknown_first[] = "ply\nformat binary_little_endian 1.0\nelement camera 1\nproperty float x\n"
                                        "element face 1\nproperty list uint int vertex_indices\nend_header\n"
                                        "\xff\xff\xff\xff\0\0\0\0";
    write_file("unknown_first.ply", unknown_first, sizeof unknown_first - 1);
    expect_refused("unknown_first.ply", VFX_ERR_FORMAT, "PLY header line 3: element camera (1) comes before element "
                   "face, and Assimp 5.2 reads an element it does not know as empty");
    /* after the mesh's elements it is harmless, and the file imports */
    static const char unknown_last[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                                       "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                                       "element camera 1\nproperty float x\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n7\n";
    write_file("unknown_last.ply", unknown_last, sizeof unknown_last - 1);
    expect_imported("unknown_last.ply", 3);
    /* Assimp ends an element's properties at a comment: y and z were dropped and every vertex
     * read (x, 0, 0), silently (a binary body would shift under it) */
    static const char comment_mid[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\ncomment hi\n"
                                      "property float y\nproperty float z\nelement face 1\n"
                                      "property list uchar int vertex_indices\nend_header\n1 2 3\n4 5 6\n7 8 9\n3 0 1 2\n";
    write_file("comment_mid.ply", comment_mid, sizeof comment_mid - 1);
    expect_refused("comment_mid.ply", VFX_ERR_FORMAT, "PLY header line 6: a property after line 5, which is not one");
    /* end_header as the file's last bytes: Assimp's header loop never ended (fuzz_mesh_ply) */
    static const char no_eol[] = "ply\nformat binary_little_endian 1.0\nelement vertex 0\nprtex_indices\nend_header";
    write_file("no_eol.ply", no_eol, sizeof no_eol - 1);
    expect_refused("no_eol.ply", VFX_ERR_FORMAT, "PLY header line 5: end_header ends the file with no line end after it");
    /* with no mesh in them, the bytes are refused by name */
    char err[256] = "";
    rt_mesh_data m;
    assert_int_equal(rt_mesh_import_memory(cr, 0, "ply", &m, err, sizeof err), VFX_ERR_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "rt_mesh_import_memory: no mesh in the bytes (0 bytes"));
}

/* A face's list count must match its indices: "3 0 1" is refused (Assimp read the missing index
 * from the next line, or left it 0), "3 0 1 2" imports; element names start with a letter. */
static void test_ply_list_counts_and_names(void **state)
{
    (void)state;
    static const char head[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                               "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                               "0 0 0\n1 0 0\n0 1 0\n";
    char buf[512];
    snprintf(buf, sizeof buf, "%s3 0 1\n", head);
    write_file("face_short.ply", buf, strlen(buf));
    expect_refused("face_short.ply", VFX_ERR_FORMAT, "element face 0, property 0: a list of 3 items, more than the line holds");
    snprintf(buf, sizeof buf, "%s3 0 1 2\n", head);
    write_file("face_ok.ply", buf, strlen(buf));
    expect_imported("face_ok.ply", 3);
    static const char *const bad_names[] = {"-vertex", ".vertex", "8vertex"};
    for (int i = 0; i < 3; ++i) {
        snprintf(buf, sizeof buf, "ply\nformat ascii 1.0\nelement %s 3\nproperty float x\nend_header\n0\n1\n2\n",
                 bad_names[i]);
        write_file("bad_name.ply", buf, strlen(buf));
        char needle[96];
        snprintf(needle, sizeof needle, "line 3: element name \"%s\" does not start with a letter", bad_names[i]);
        expect_refused("bad_name.ply", VFX_ERR_FORMAT, needle);
    }
}

/* A glTF of `nodes` nodes: node i's children are the next `fan` nodes ("chain": fan 1), or
 * node 0 holds all the others; each node may place mesh 0 (one triangle, its POSITION count
 * `claimed`), whose buffer is embedded as base64. */
static char *gltf_nodes(unsigned nodes, int chain, unsigned claimed)
{
    size_t cap = 1024 + (size_t)nodes * 40;
    char *g = malloc(cap);
    assert_non_null(g);
    size_t n = (size_t)snprintf(g, cap, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
                                        "\"nodes\":[");
    for (unsigned i = 0; i < nodes; ++i) {
        n += (size_t)snprintf(g + n, cap - n, "%s{\"mesh\":0", i ? "," : "");
        if (chain && i + 1 < nodes)
            n += (size_t)snprintf(g + n, cap - n, ",\"children\":[%u]", i + 1);
        if (!chain && i == 0 && nodes > 1) {
            n += (size_t)snprintf(g + n, cap - n, ",\"children\":[");
            for (unsigned k = 1; k < nodes; ++k)
                n += (size_t)snprintf(g + n, cap - n, "%s%u", k > 1 ? "," : "", k);
            n += (size_t)snprintf(g + n, cap - n, "]");
        }
        n += (size_t)snprintf(g + n, cap - n, "}");
    }
    /* three vertices (0,0,0) (1,0,0) (0,1,0), 36 bytes */
    snprintf(g + n, cap - n, "],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":%u,\"type\":\"VEC3\","
             "\"min\":[0,0,0],\"max\":[1,1,0]}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
             "\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,"
             "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}]}", claimed);
    return g;
}

/* The attacks of issue 37 on glTF node trees, each refused in well under a second, the import
 * process included, at a small peak RSS (test_memory_stayed_bounded). */
static void test_gltf_node_trees(void **state)
{
    (void)state;
    /* a chain 20,000 deep: Assimp's recursive reader overflowed the stack (SIGSEGV) */
    char *g = gltf_nodes(20000, 1, 3);
    write_file("chain.gltf", g, strlen(g));
    expect_refused("chain.gltf", VFX_ERR_FORMAT, "glTF node 65 lies deeper than 64 nodes below a root");
    /* the same bytes with the checks skipped: Assimp's own crash, contained in the import process */
    rt_mesh_data m;
    char err[600] = "";
    double t0 = cpu_s();
    assert_int_equal(rt_mesh_import_memory_ex(g, strlen(g), "gltf", NULL, RT_MESH_IMPORT_UNCHECKED, &m, err, sizeof err),
                     VFX_ERR_FORMAT);
    printf("chain.gltf unchecked: %s (%.2f s CPU)\n", err, cpu_s() - t0);
    assert_non_null(strstr(err, "(memory).gltf: the reader crashed (SIGSEGV"));
    assert_null(m.positions);
    free(g);
    /* an instancing bomb scaled down: 70,000 nodes each placing the triangle (1.2 M nodes took 38 s
     * and 2.7 GB before), and 50 nodes placing a mesh claiming 100,000 vertices (5 M placed) */
    g = gltf_nodes(70000, 0, 3);
    write_file("bomb.gltf", g, strlen(g));
    expect_refused("bomb.gltf", VFX_ERR_FORMAT, "glTF: 70000 nodes, above the cap of 65536");
    free(g);
    g = gltf_nodes(50, 0, 100000);
    write_file("placed.gltf", g, strlen(g));
    expect_refused("placed.gltf", VFX_ERR_FORMAT, "glTF: 5000000 vertices once every node's mesh is placed (50 nodes)");
    free(g);
    /* a node with two parents (placed twice, and everything below it twice again) */
    static const char dag[] = "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"children\":[2]},{\"children\":[2]},{}]}";
    write_file("dag.gltf", dag, sizeof dag - 1);
    expect_refused("dag.gltf", VFX_ERR_FORMAT, "glTF node 2 is a child of node 0 and of node 1");
    /* a small tree imports: the triangle placed by 3 nodes */
    g = gltf_nodes(3, 0, 3);
    write_file("three.gltf", g, strlen(g));
    expect_imported("three.gltf", 9);
    free(g);
}

static void le32(unsigned char *p, uint32_t v)
{
    for (int i = 0; i < 4; ++i)
        p[i] = (unsigned char)(v >> (8 * i));
}

static void test_glb_claiming_4gb(void **state)
{
    (void)state;
    /* 22 bytes: header and JSON chunk both claim ~4 GB (Assimp: 4.2 GB peak, 27 s) */
    unsigned char g[22] = {'g', 'l', 'T', 'F'};
    le32(g + 4, 2), le32(g + 8, 0xFFFFFFF0u), le32(g + 12, 0xFFFFFFF0u);
    memcpy(g + 16, "JSON{}", 6);
    write_file("huge.glb", g, sizeof g);
    expect_refused("huge.glb", VFX_ERR_FORMAT, "claims 4294967280 bytes");
    le32(g + 8, sizeof g); /* an honest total, the chunk still lying */
    write_file("huge_chunk.glb", g, sizeof g);
    expect_refused("huge_chunk.glb", VFX_ERR_FORMAT, "chunk 0 at byte 12 claims 4294967280 bytes");
    le32(g + 4, 1);
    write_file("v1.glb", g, sizeof g);
    expect_refused("v1.glb", VFX_ERR_FORMAT, "only glTF 2.0");
}

static void test_stl_counts(void **state)
{
    (void)state;
    /* 2^31 + 1 triangles: 84 + 50 N wraps in 32 bits to the 134 bytes the file has */
    unsigned char s[134] = {0};
    le32(s + 80, 0x80000001u);
    write_file("wrap.stl", s, sizeof s);
    expect_refused("wrap.stl", VFX_ERR_FORMAT, "claims 2147483649 triangles");
    le32(s + 80, 1000);
    write_file("short.stl", s, 84);
    expect_refused("short.stl", VFX_ERR_FORMAT, "not an STL file");
}

static void test_obj_corner_cap(void **state)
{
    (void)state;
    /* "f 1 1 1" is 8 bytes and 3 Assimp vertices: 400,000 lines are 1.2 M, over the cap */
    size_t lines = 400000, n = 8 + 8 * lines;
    char *buf = malloc(n);
    assert_non_null(buf);
    memcpy(buf, "v 0 0 0\n", 8);
    for (size_t i = 0; i < lines; ++i)
        memcpy(buf + 8 + 8 * i, "f 1 1 1\n", 8);
    write_file("corners.obj", buf, n);
    free(buf);
    expect_refused("corners.obj", VFX_ERR_FORMAT, "1200000 face corners");
}

static void test_files_beside_the_mesh(void **state)
{
    (void)state;
    unlink("pipe.mtl");
    assert_int_equal(mkfifo("pipe.mtl", 0600), 0);
    static const char obj[] = "mtllib pipe.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    write_file("with_fifo_mtl.obj", obj, sizeof obj - 1);
    expect_refused("with_fifo_mtl.obj", VFX_ERR_IO, "pipe.mtl: is a FIFO");
    static const char gltf[] =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],"
        "\"buffers\":[{\"byteLength\":36,\"uri\":\"/dev/zero\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],"
        "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}]}";
    write_file("devzero.gltf", gltf, sizeof gltf - 1);
    expect_refused("devzero.gltf", VFX_ERR_IO, "/dev/zero: is a character device");
    /* a missing .mtl stays what it was: the mesh imports without it */
    static const char obj2[] = "mtllib not_there.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    write_file("missing_mtl.obj", obj2, sizeof obj2 - 1);
    expect_imported("missing_mtl.obj", 3);
    unlink("pipe.mtl");
}

static void test_disabled_formats(void **state)
{
    (void)state;
    static const char off[] = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    write_file("tri.off", off, sizeof off - 1);
    expect_refused("tri.off", VFX_ERR_FORMAT, ".off is not a mesh format the game imports");
    write_file("noext", off, sizeof off - 1);
    expect_refused("noext", VFX_ERR_FORMAT, "no file extension");
    static const char gltf1[] = "{\"asset\":{\"version\":\"1.0\"},\"scene\":\"s\",\"scenes\":{\"s\":{\"nodes\":[]}}}";
    write_file("v1.gltf", gltf1, sizeof gltf1 - 1);
    expect_refused("v1.gltf", VFX_ERR_FORMAT, "only glTF 2.0");
    /* a PLY named .obj is parsed as OBJ, never handed to another importer: no triangle */
    unsigned char buf[512] = {0};
    int n = snprintf((char *)buf, sizeof buf, ply_head, "3", "1");
    write_file("ply_named.obj", buf, (size_t)n);
    expect_refused("ply_named.obj", VFX_ERR_FORMAT, "ply_named.obj");
}

/* One triangle (0,0,0) (1,0,0) (0,1,0) in each enabled format. */
static void expect_triangle(const char *path)
{
    rt_mesh_data m;
    char err[600] = "";
    if (rt_mesh_import(path, &m, err, sizeof err) != VFX_OK)
        fail_msg("%s: %s", path, err);
    assert_int_equal(m.index_count, 3);
    assert_true(m.bounds_max[0] == 1.f && m.bounds_max[1] == 1.f && m.bounds_min[0] == 0.f);
    rt_mesh_data_free(&m);
}

static void test_valid_files_of_each_format(void **state)
{
    (void)state;
    static const float tri[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    unsigned char buf[1024] = {0};
    /* binary PLY */
    int n = snprintf((char *)buf, sizeof buf, ply_head, "3", "1");
    memcpy(buf + n, tri, sizeof tri);
    n += (int)sizeof tri;
    buf[n++] = 3;
    for (int32_t i = 0; i < 3; ++i, n += 4)
        memcpy(buf + n, &i, 4);
    write_file("tri_bin.ply", buf, (size_t)n);
    expect_triangle("tri_bin.ply");
    static const char ascii[] = "ply\r\nformat ascii 1.0\r\ncomment made by a test\r\nelement vertex 3\r\n"
                                "property float x\r\nproperty float y\r\nproperty float z\r\nelement face 1\r\n"
                                "property list uchar int vertex_indices\r\nend_header\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2";
    write_file("tri_ascii.ply", ascii, sizeof ascii - 1);
    expect_triangle("tri_ascii.ply");
    /* binary STL: 80-byte header, count, then normal, 3 vertices, attribute */
    memset(buf, 0, sizeof buf);
    le32(buf + 80, 1);
    memcpy(buf + 84 + 12, tri, sizeof tri);
    write_file("tri_bin.stl", buf, 134);
    expect_triangle("tri_bin.stl");
    static const char stl[] = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                              "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    write_file("tri_ascii.stl", stl, sizeof stl - 1);
    expect_triangle("tri_ascii.stl");
    static const char obj[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    write_file("tri.obj", obj, sizeof obj - 1);
    expect_triangle("tri.obj");
    /* glb: JSON chunk (padded with spaces to 4 bytes) then the BIN chunk of the positions */
    static const char json[] =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],\"nodes\":[{\"mesh\":0}],"
        "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"buffers\":[{\"byteLength\":36}],"
        "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,"
        "\"componentType\":5126,\"count\":3,\"type\":\"VEC3\",\"min\":[0,0,0],\"max\":[1,1,0]}]}";
    size_t jl = (sizeof json - 1 + 3) & ~(size_t)3, total = 12 + 8 + jl + 8 + sizeof tri;
    memset(buf, ' ', sizeof buf);
    memcpy(buf, "glTF", 4), le32(buf + 4, 2), le32(buf + 8, (uint32_t)total);
    le32(buf + 12, (uint32_t)jl), memcpy(buf + 16, "JSON", 4), memcpy(buf + 20, json, sizeof json - 1);
    le32(buf + 20 + jl, sizeof tri), memcpy(buf + 24 + jl, "BIN\0", 4), memcpy(buf + 28 + jl, tri, sizeof tri);
    write_file("tri.glb", buf, total);
    expect_triangle("tri.glb");
    /* .gltf with its buffer in a .bin beside it (read through the same checks) */
    write_file("tri.bin", tri, sizeof tri);
    char gltf[1024];
    snprintf(gltf, sizeof gltf, "%.*s", (int)(strstr(json, "\"buffers\"") - json), json);
    strcat(gltf, "\"buffers\":[{\"byteLength\":36,\"uri\":\"tri.bin\"}]");
    strcat(gltf, strstr(json, ",\"bufferViews\""));
    write_file("tri.gltf", gltf, strlen(gltf));
    expect_triangle("tri.gltf");
}

static void test_memory_stayed_bounded(void **state)
{
    (void)state;
    /* every case above in one process: the peak RSS stays that of a small program (a 4 GB
     * claim that got through would show here even if it failed later) */
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    assert_true(ru.ru_maxrss < 256 * 1024);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_truncated_binary_ply), cmocka_unit_test(test_ply_claiming_2e9_vertices),
        cmocka_unit_test(test_glb_claiming_4gb),     cmocka_unit_test(test_stl_counts),
        cmocka_unit_test(test_obj_corner_cap),       cmocka_unit_test(test_files_beside_the_mesh),
        cmocka_unit_test(test_disabled_formats),     cmocka_unit_test(test_valid_files_of_each_format),
        cmocka_unit_test(test_ply_list_counts_and_names), cmocka_unit_test(test_gltf_node_trees),
        cmocka_unit_test(test_non_finite_vertices), cmocka_unit_test(test_memory_stayed_bounded),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
