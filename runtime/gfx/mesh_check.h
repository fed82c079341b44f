/* mesh_check.h — what a mesh file must show before Assimp reads it: an enabled format (by
 * name, confirmed by the bytes), and header counts the file's size can hold. Assimp trusts the
 * counts it reads and allocates them (a .glb claiming a 4 GB chunk, a PLY claiming 2e9
 * vertices), so they are checked here first. GL-free and Assimp-free: the fuzzers and the
 * tests call it directly. */
#ifndef RT_MESH_CHECK_H
#define RT_MESH_CHECK_H

#include <stddef.h>
#include <stdint.h>
#include <volfx/volfx.h>

/* Caps of one import (docs/robustness.md has the measured memory they bound): every file
 * Assimp opens for one mesh (the mesh, an .mtl, a .bin) together at most RT_MESH_MAX_BYTES,
 * and at most RT_MESH_MAX_IMPORT_VERTICES vertices before post-processing (which holds about
 * 700 bytes per vertex: 0.7 GB at the cap). */
#define RT_MESH_MAX_BYTES (32u * 1024u * 1024u)
#define RT_MESH_MAX_BYTES_TEXT "32 MiB"
#define RT_MESH_MAX_IMPORT_VERTICES (1u << 20)
/* What the game holds once every node's meshes are placed (a mesh instanced by many nodes is
 * copied per node): 4 M vertices are 96 MB of positions and normals. */
#define RT_MESH_MAX_PLACED_VERTICES (4u * RT_MESH_MAX_IMPORT_VERTICES)
/* glTF node trees: Assimp 5.2 reads them recursively (a chain 20,000 deep overflowed its stack)
 * and builds every node (1.2 M nodes took 38 s and 2.7 GB), so both are checked before it. */
#define RT_MESH_MAX_NODES 65536u
#define RT_MESH_MAX_NODE_DEPTH 64u

/* The formats the game imports; everything else Assimp knows is refused by name. */
typedef enum rt_mesh_format {
    RT_MESH_FORMAT_NONE = 0,
    RT_MESH_FORMAT_OBJ,
    RT_MESH_FORMAT_PLY,
    RT_MESH_FORMAT_STL,
    RT_MESH_FORMAT_GLTF, /* glTF 2.0 JSON */
    RT_MESH_FORMAT_GLB,  /* glTF 2.0 binary */
} rt_mesh_format;

/* The format a file name's extension names (case-insensitive), or RT_MESH_FORMAT_NONE. */
rt_mesh_format rt_mesh_format_of_name(const char *name);
/* The extension Assimp is given for a format ("obj", ...); NULL for RT_MESH_FORMAT_NONE. */
const char *rt_mesh_format_ext(rt_mesh_format f);

/* Checks that `data` (size bytes, the whole file) is a `f` file whose header counts fit in it:
 * PLY's magic, format and every element's minimum bytes (binary: fixed sizes; ASCII: two
 * characters a value) against the body, STL's 84 + 50 x N bytes (binary) or "solid" (ASCII),
 * glb's header length and every chunk against the file, glTF's node tree (glb and .gltf: at most
 * RT_MESH_MAX_NODES nodes forming a tree at most RT_MESH_MAX_NODE_DEPTH deep, and at most
 * RT_MESH_MAX_PLACED_VERTICES vertices once each node's mesh is placed). Fails with VFX_ERR_FORMAT and "NAME:
 * ..." saying which count claims what and what the file holds. */
vfx_result rt_mesh_check_bytes(rt_mesh_format f, const unsigned char *data, size_t size,
                               const char *name, char *err, size_t errlen);

#endif
