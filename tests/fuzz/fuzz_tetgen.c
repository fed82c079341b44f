/* fuzz_tetgen.c — libFuzzer target: TetGen .node + .ele. The loader takes only a path base, so the
 * input is split at its first 0 byte (or halfway when there is none) into X.node and X.ele in a
 * temp dir made once per process. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "scene/volume_file.h"

static int write_file(const char *path, const uint8_t *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return -1;
    size_t n = size ? fwrite(data, 1, size, f) : 0;
    int rc = fclose(f);
    return (n == size && rc == 0) ? 0 : -1;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    /* libFuzzer's entry point has no init argument; the temp dir is the one piece of process
     * state, made on the first call (a fuzz target, not library code). */
    static char dir[64];
    if (!dir[0]) {
        strcpy(dir, "/tmp/vfx-fuzz-tetgen-XXXXXX");
        if (!mkdtemp(dir))
            abort();
    }
    const uint8_t *zero = memchr(data, 0, size);
    size_t node_len = zero ? (size_t)(zero - data) : size / 2;
    size_t ele_off = zero ? node_len + 1 : node_len;
    char base[96], path[112];
    snprintf(base, sizeof base, "%s/X", dir);
    snprintf(path, sizeof path, "%s.node", base);
    if (write_file(path, data, node_len) != 0)
        abort();
    snprintf(path, sizeof path, "%s.ele", base);
    if (write_file(path, data + ele_off, size - ele_off) != 0)
        abort();
    char err[256];
    /* "attr0" reaches the node-attribute scalar path; NULL the plain geometry path. */
    const char *names[2] = {NULL, "attr0"};
    for (int i = 0; i < 2; i++) {
        tet_mesh mesh;
        if (rt_volume_load_tetgen(base, names[i], &mesh, err, sizeof err) == VFX_OK)
            tet_mesh_free(&mesh);
    }
    return 0;
}
