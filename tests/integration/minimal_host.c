/* minimal_host.c — a game engine's view of volfx: its own EGL context, its own framebuffers,
 * plain C arrays for particles and beams. Nothing from runtime/.
 * usage: minimal_host [libvolfx.so.2 | path/to/libvolfx.so]
 * With an argument the plugin is loaded with dlopen (a bare soname goes through the loader's
 * search path); without one the host calls the vfx_plugin_entry it was linked against
 * (cc minimal_host.c $(pkg-config --cflags --libs volfx) ...).
 * Exits 0 when every effect the plugin has built drew something where expected, 77 when no
 * GL context can be made. */
#include <dlfcn.h>
#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <volfx/volfx.h>

#define W 96
#define H 64
#define NP 512

typedef struct game {
    float x[NP], y[NP], z[NP]; /* the game's own particle arrays */
    vfx_beam beam;
    uint64_t frame;
    int errors;
} game;

static void on_log(void *user, vfx_log_level level, vfx_log_id id, const char *msg)
{
    (void)id; /* the text is enough for this host */
    game *g = user;
    if (level >= VFX_LOG_WARN)
        fprintf(stderr, "volfx: %s\n", msg);
    if (level == VFX_LOG_ERROR)
        g->errors++;
}
static void *on_proc(void *user, const char *name) { (void)user; return (void *)eglGetProcAddress(name); }
static uint32_t on_chunks(void *user) { (void)user; return 1; }
static vfx_result on_chunk(void *user, uint32_t i, vfx_particle_view *v)
{
    game *g = user;
    if (i != 0)
        return VFX_ERR_NOT_FOUND;
    *v = (vfx_particle_view){.type = VFX_TYPE_PARTICLE_VIEW, .count = NP,
                             .pos = {g->x, g->y, g->z}, .revision = g->frame};
    return VFX_OK;
}
static vfx_result on_beams(void *user, vfx_beams_view *v)
{
    game *g = user;
    *v = (vfx_beams_view){.type = VFX_TYPE_BEAMS_VIEW, .count = 1, .beams = &g->beam};
    return VFX_OK;
}

static bool make_context(void)
{
    EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (d == EGL_NO_DISPLAY || !eglInitialize(d, NULL, NULL) || !eglBindAPI(EGL_OPENGL_API))
        return false;
    const EGLint a[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext c = eglCreateContext(d, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, a);
    return c != EGL_NO_CONTEXT && eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c);
}

int main(int argc, char **argv)
{
    if (!make_context()) {
        fprintf(stderr, "no GL 4.5 context: skipping\n");
        return 77;
    }
    static game g;
    for (int i = 0; i < NP; ++i) { /* a 8x8x8 block of water in front of the camera */
        g.x[i] = -0.6f + 0.15f * (i % 8);
        g.y[i] = -0.6f + 0.15f * ((i / 8) % 8);
        g.z[i] = -0.6f + 0.15f * (i / 64);
    }
    g.beam = (vfx_beam){.type = VFX_TYPE_BEAM, .head = {-2, 1.2f, 0}, .dir = {1, 0, 0}, .length = 4, .radius = 1,
                        .a = 0.5f, .b = 0.5f, .eps = 0.05f};
    vfx_context_desc host = {.type = VFX_TYPE_CONTEXT_DESC, .user = &g,
                         .gl_get_proc_address = on_proc, .log = on_log, .particle_chunk_count = on_chunks,
                         .particle_chunk = on_chunk, .beams = on_beams};
    vfx_plugin_entry_fn entry = vfx_plugin_entry; /* linked: -lvolfx */
    void *lib = NULL;
    if (argc > 1) {
        lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
        void *sym = lib ? dlsym(lib, VFX_ENTRY_SYMBOL) : NULL;
        if (!sym) {
            fprintf(stderr, "cannot load %s: %s\n", argv[1], dlerror());
            return 1;
        }
        memcpy(&entry, &sym, sizeof entry); /* object-to-function pointer, as POSIX allows */
    }
    vfx_plugin_api api = {.type = VFX_TYPE_PLUGIN_API};
    if (entry(VFX_ABI_VERSION, &host, &api) != VFX_OK)
        return 1;
    vfx_context *ctx;
    if (api.create(&host, &ctx) != VFX_OK)
        return 1;
    /* the engine's targets: scene colour+depth it rendered, and an output it presents */
    GLuint scene_c, scene_d, out_c, out_fbo, scene_fbo;
    glCreateTextures(GL_TEXTURE_2D, 1, &scene_c);
    glTextureStorage2D(scene_c, 1, GL_RGBA8, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &scene_d);
    glTextureStorage2D(scene_d, 1, GL_DEPTH_COMPONENT32F, W, H);
    glCreateTextures(GL_TEXTURE_2D, 1, &out_c);
    glTextureStorage2D(out_c, 1, GL_RGBA8, W, H);
    glCreateFramebuffers(1, &scene_fbo);
    glNamedFramebufferTexture(scene_fbo, GL_COLOR_ATTACHMENT0, scene_c, 0);
    glNamedFramebufferTexture(scene_fbo, GL_DEPTH_ATTACHMENT, scene_d, 0);
    glCreateFramebuffers(1, &out_fbo);
    glNamedFramebufferTexture(out_fbo, GL_COLOR_ATTACHMENT0, out_c, 0);
    /* camera at z = 4 looking at the origin, 60 degrees, GL conventions */
    float f = 1.f / tanf(0.5f * 1.0472f), n = 0.1f, fa = 50.f;
    vfx_frame_view fv = {.type = VFX_TYPE_FRAME_VIEW, .framebuffer = out_fbo,
                         .color_texture = scene_c, .depth_texture = scene_d, .width = W, .height = H,
                         .view = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, -4, 1},
                         .proj = {f * H / W, 0, 0, 0, 0, f, 0, 0, 0, 0, -(fa + n) / (fa - n), -1, 0, 0, -2 * fa * n / (fa - n), 0},
                         .eye = {0, 0, 4}, .near_plane = n, .far_plane = fa, .fov_y = 1.0472f};
    for (int frame = 0; frame < 3; ++frame) {
        g.frame = (uint64_t)frame;
        glBindFramebuffer(GL_FRAMEBUFFER, scene_fbo); /* the engine's opaque pass: empty sky */
        glClearColor(0, 0, 0, 1);
        glClearDepth(1);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glBlitNamedFramebuffer(scene_fbo, out_fbo, 0, 0, W, H, 0, 0, W, H, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        if (api.update(ctx, frame / 60.0, 1.f / 60.f) || api.render(ctx, &fv)) {
            fprintf(stderr, "frame %d: %s\n", frame, api.last_error(ctx, NULL));
            return 1;
        }
    }
    static unsigned char px[W * H * 4];
    glGetTextureImage(out_c, 0, GL_RGBA, GL_UNSIGNED_BYTE, sizeof px, px);
    int lit = 0;
    for (int i = 0; i < W * H; ++i)
        lit += px[4 * i] + px[4 * i + 1] + px[4 * i + 2] > 30;
    vfx_stats st = {.type = VFX_TYPE_STATS};
    api.get_stats(ctx, &st);
    printf("effects built 0x%x, %d of %d pixels lit, %u stats, %d errors\n", api.effects_built, lit,
           W * H, st.count, g.errors);
    api.destroy(ctx);
    if (lib)
        dlclose(lib);
    if (g.errors)
        return 1;
    /* with an effect built, something must be drawn; with none, nothing may be */
    if (api.effects_built & (VFX_EFFECT_BIT(VFX_EFFECT_WATER) | VFX_EFFECT_BIT(VFX_EFFECT_BEAMS)))
        return lit > 0 ? 0 : 1;
    return lit == 0 ? 0 : 1;
}
