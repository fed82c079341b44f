/* Assimp import of Debian's assimp-testmodels, and corrupt files giving errors that name the
 * file. Exits 77 when assimp-testmodels is not installed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gfx/mesh_import.h"

#define MODELS "/usr/share/assimp/models"

static void test_box_obj(void **state)
{
    (void)state;
    rt_mesh_data m;
    char err[512];
    assert_int_equal(rt_mesh_import(MODELS "/OBJ/box.obj", &m, err, sizeof err), VFX_OK);
    /* a unit box: 12 triangles, bounds +-0.5 (the file's own coordinates) */
    assert_int_equal(m.index_count, 36);
    for (int a = 0; a < 3; ++a) {
        assert_true(fabsf(m.bounds_min[a] + 0.5f) < 1e-6f);
        assert_true(fabsf(m.bounds_max[a] - 0.5f) < 1e-6f);
    }
    for (uint32_t i = 0; i < m.vertex_count; ++i) {
        float *n = &m.normals[3 * i];
        assert_true(fabsf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.f) < 1e-4f);
    }
    rt_mesh_data_free(&m);
}

static void test_other_formats(void **state)
{
    (void)state;
    static const char *files[] = {MODELS "/PLY/cube.ply", MODELS "/PLY/cube_binary.ply", MODELS "/PLY/Wuson.ply",
                                  MODELS "/STL/Spider_ascii.stl", MODELS "/OBJ/spider.obj",
                                  MODELS "/glTF2/BoxTextured-glTF/BoxTextured.gltf",
                                  MODELS "/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb",
                                  MODELS "/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"};
    for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
        FILE *f = fopen(files[i], "rb");
        if (!f)
            continue;
        fclose(f);
        rt_mesh_data m;
        char err[512];
        vfx_result r = rt_mesh_import(files[i], &m, err, sizeof err);
        if (r != VFX_OK)
            fail_msg("%s: %s", files[i], err);
        assert_true(m.index_count > 0 && m.index_count % 3 == 0);
        for (uint32_t k = 0; k < m.index_count; ++k)
            assert_true(m.indices[k] < m.vertex_count);
        rt_mesh_data_free(&m);
    }
    /* issue 28: the formats the game does not use are refused before Assimp reads them */
    rt_mesh_data m;
    char err[512];
    FILE *f3 = fopen(MODELS "/3DS/fels.3ds", "rb");
    if (f3) {
        fclose(f3);
        assert_int_equal(rt_mesh_import(MODELS "/3DS/fels.3ds", &m, err, sizeof err), VFX_ERR_FORMAT);
        assert_non_null(strstr(err, ".3ds is not a mesh format the game imports"));
    }
}

static void test_corrupt_files(void **state)
{
    (void)state;
    rt_mesh_data m;
    char err[512];
    assert_int_equal(rt_mesh_import(MODELS "/invalid/malformed.obj", &m, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "malformed.obj"));
    assert_null(m.positions);
    assert_int_equal(rt_mesh_import(MODELS "/invalid/empty.obj", &m, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "empty.obj"));
    assert_int_equal(rt_mesh_import("/no/such/file.obj", &m, err, sizeof err), VFX_ERR_IO);
    assert_non_null(strstr(err, "/no/such/file.obj"));
    /* truncated binary STL: header says 1000 triangles, body holds none */
    unsigned char stl[84] = {0};
    stl[80] = 0xe8, stl[81] = 0x03;
    FILE *f = fopen("truncated.stl", "wb");
    fwrite(stl, 1, sizeof stl, f);
    fclose(f);
    assert_int_equal(rt_mesh_import("truncated.stl", &m, err, sizeof err), VFX_ERR_FORMAT);
    assert_non_null(strstr(err, "truncated.stl"));
    static const char garbage[] = "v 1 2\nf 1 2 3 4 5\nv nan nan nan\n";
    vfx_result r = rt_mesh_import_memory(garbage, sizeof garbage - 1, "obj", &m, err, sizeof err);
    assert_int_not_equal(r, VFX_OK);
}

int main(void)
{
    FILE *f = fopen(MODELS "/OBJ/box.obj", "rb");
    if (!f) {
        fprintf(stderr, "assimp-testmodels not installed: skipping\n");
        return 77;
    }
    fclose(f);
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_box_obj),
        cmocka_unit_test(test_other_formats),
        cmocka_unit_test(test_corrupt_files),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
