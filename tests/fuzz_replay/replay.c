/* replay.c — runs a libFuzzer target's LLVMFuzzerTestOneInput on every file of its seed corpus
 * (tests/fuzz/corpus/<target>/), built with the normal compiler: the inputs the fuzzers found
 * (crashes, leaks, NaN pixels) stay regression tests of the main and sanitizer suites, which
 * run without clang or libFuzzer. usage: replay_<target> CORPUS_DIR */
#define _POSIX_C_SOURCE 200809L
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]);
        return 2;
    }
    DIR *d = opendir(argv[1]);
    if (!d) {
        perror(argv[1]);
        return 1;
    }
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) {
        if (e->d_name[0] == '.')
            continue;
        char path[4096];
        snprintf(path, sizeof path, "%s/%s", argv[1], e->d_name);
        FILE *f = fopen(path, "rb");
        if (!f)
            continue;
        fseek(f, 0, SEEK_END);
        long len = ftell(f);
        fseek(f, 0, SEEK_SET);
        uint8_t *buf = malloc(len > 0 ? (size_t)len : 1);
        size_t got = buf && len > 0 ? fread(buf, 1, (size_t)len, f) : 0;
        fclose(f);
        printf("%s (%zu bytes)\n", e->d_name, got);
        fflush(stdout);
        LLVMFuzzerTestOneInput(buf, got); /* aborts (a failed test) on a finding */
        free(buf);
        n++;
    }
    closedir(d);
    printf("%d inputs replayed\n", n);
    return n > 0 ? 0 : 1;
}
