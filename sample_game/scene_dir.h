/* scene_dir.h — where the game's scenes and their data are: the source tree's sample_game/scenes
 * for a game run from its build tree, the install's share/volfx/scenes otherwise (found from the
 * executable's own path, so an install moved elsewhere or unpacked from a DESTDIR works too, then
 * the configured prefix's), VFX_SCENE_DIR over all of them. */
#ifndef GAME_SCENE_DIR_H
#define GAME_SCENE_DIR_H

#include <stddef.h>

/* Writes the scenes folder into buf (cap bytes) and returns buf. */
const char *game_scene_dir(char *buf, size_t cap);
/* A --scene argument as a path: `arg` itself when it names an existing file or has a '/'; else
 * a bare name found in game_scene_dir (written into buf); else `arg` (its open error is then the
 * message). */
const char *game_scene_resolve(const char *arg, char *buf, size_t cap);

#endif
