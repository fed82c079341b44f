/* scene_dir.c — the scenes folder of a build-tree or an installed game (scene_dir.h). */
#include "scene_dir.h"

#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* Set by sample_game/meson.build: the source scenes, the build root, the install's scenes
 * relative to its bindir and absolute under the configured prefix. */
#ifndef GAME_SCENE_DIR
#define GAME_SCENE_DIR "."
#endif
#ifndef GAME_BUILD_ROOT
#define GAME_BUILD_ROOT ""
#endif
#ifndef GAME_DATA_REL
#define GAME_DATA_REL "../share/volfx/scenes"
#endif
#ifndef GAME_DATA_DIR
#define GAME_DATA_DIR "/usr/local/share/volfx/scenes"
#endif

static bool is_dir(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

/* The folder of the running executable (Linux: /proc/self/exe), "" when unknown. */
static void exe_dir(char *buf, size_t cap)
{
    ssize_t n = cap > 1 ? readlink("/proc/self/exe", buf, cap - 1) : -1;
    if (n <= 0 || (size_t)n >= cap - 1) {
        buf[0] = '\0';
        return;
    }
    buf[n] = '\0';
    char *slash = strrchr(buf, '/');
    if (slash)
        *slash = '\0';
    else
        buf[0] = '\0';
}

const char *game_scene_dir(char *buf, size_t cap)
{
    const char *env = getenv("VFX_SCENE_DIR");
    if (env && *env) {
        snprintf(buf, cap, "%s", env);
        return buf;
    }
    char exe[4096];
    exe_dir(exe, sizeof exe);
    size_t root = strlen(GAME_BUILD_ROOT);
    /* an executable inside the build tree: the tree's own scenes, edits and all */
    static const char build_root[] = GAME_BUILD_ROOT;
    if (root && strlen(exe) >= root && memcmp(exe, build_root, root) == 0 && (exe[root] == '/' || exe[root] == '\0')) {
        snprintf(buf, cap, "%s", GAME_SCENE_DIR);
        return buf;
    }
    /* installed: beside the executable's bindir, wherever the prefix now is */
    if (exe[0] && GAME_DATA_REL[0] != '/') {
        char rel[4096 + sizeof GAME_DATA_REL + 1], abs_[PATH_MAX];
        snprintf(rel, sizeof rel, "%s/%s", exe, GAME_DATA_REL);
        if (is_dir(rel)) { /* named without the bin/.. detour when it resolves */
            snprintf(buf, cap, "%s", realpath(rel, abs_) ? abs_ : rel);
            return buf;
        }
    }
    snprintf(buf, cap, "%s", GAME_DATA_DIR);
    return buf;
}

const char *game_scene_resolve(const char *arg, char *buf, size_t cap)
{
    if (!arg || strchr(arg, '/') || access(arg, F_OK) == 0)
        return arg;
    char dir[4096];
    game_scene_dir(dir, sizeof dir);
    int w = snprintf(buf, cap, "%s/%s", dir, arg);
    return w > 0 && (size_t)w < cap && access(buf, F_OK) == 0 ? buf : arg;
}
