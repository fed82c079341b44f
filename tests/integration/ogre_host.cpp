// ogre_host.cpp — volfx in an OGRE 1.12 application (GL3Plus render system, OGRE's own GLX
// window and context). OGRE renders its scene (a floor, a wall standing in front of the effects,
// a spinning cube, a light) into a render texture as any OGRE application does; a
// RenderTargetListener hands that target's colour texture and depth (OGRE's GL names) to volfx
// after OGRE has drawn it, and volfx composites water, a beam and a volume into a second OGRE
// render texture. The host does no GL state save or restore: it calls no GL function at all
// (copies and read-backs go through OGRE's API); the plugin's GL state contract keeps OGRE's
// state cache true (docs/ogre.md).
//
// usage: ogre_host [--no-volfx] [--frames N] [--target FILE] [--output FILE] [--skip-restore]
//                  [--no-depth-check]
//   --no-volfx      OGRE alone: the run the OGRE target is compared with
//   --target FILE   OGRE's own render target after frame N (default 30), as a PPM
//   --output FILE   the composited image after frame N, as a PPM
//   --skip-restore  chain vfx_gl_state_desc.skip_restore = 1 (a planted bug: OGRE's target
//                   must then differ from the run without volfx)
//   --no-depth-check  skip check 1 below
// With volfx, after frame N it checks that each effect is drawn where OGRE's depth lets it be:
// rendered alone, each covers pixels in front of OGRE's geometry, covers pixels where the wall
// stands when the wall is hidden, and none where the wall stands when it is shown.
// Exits 0 on success, 1 on a failed check, 77 when OGRE finds no display or GL context.
#include <Ogre.h>
#include <OgreDepthBuffer.h>
#include <OgreRenderTargetListener.h>

#include <GL/glx.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <volfx/volfx.h>

namespace {

double now_s()
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

constexpr int W = 320, H = 180, NP = 2048;

// The game's data, in the game's own arrays: a still block of water, one beam, a cube of five
// tetrahedra (the SDL host's), all behind the wall at z = 1.2.
struct game {
    float x[NP], y[NP], z[NP];
    uint32_t count = 0;
    vfx_beam beam;
    float points[8 * 3], scalar[8];
    uint32_t tets[5 * 4];
    int errors = 0;
};

void on_log(void *user, vfx_log_level level, vfx_log_id id, const char *msg)
{
    auto *g = static_cast<game *>(user);
    if (level >= VFX_LOG_WARN)
        std::fprintf(stderr, "volfx (id %d): %s\n", static_cast<int>(id), msg);
    if (level == VFX_LOG_ERROR)
        g->errors++;
}
// The plugin resolves its GL functions in OGRE's GLX context, as OGRE does.
void *on_proc(void *, const char *name)
{
    return reinterpret_cast<void *>(glXGetProcAddressARB(reinterpret_cast<const GLubyte *>(name)));
}
uint32_t on_chunks(void *) { return 1; }
vfx_result on_chunk(void *user, uint32_t i, vfx_particle_view *v)
{
    auto *g = static_cast<game *>(user);
    if (i != 0)
        return VFX_ERR_NOT_FOUND;
    v->count = g->count;
    v->pos[0] = g->x, v->pos[1] = g->y, v->pos[2] = g->z;
    v->revision = 1; // still water: uploaded once
    return VFX_OK;
}
vfx_result on_water(void *, vfx_water_params *p)
{
    p->method = VFX_WATER_METHOD_TILE;
    return VFX_OK;
}
vfx_result on_beams(void *user, vfx_beams_view *v)
{
    v->count = 1;
    v->beams = &static_cast<game *>(user)->beam;
    return VFX_OK;
}
uint32_t on_volumes(void *) { return 1; }
vfx_result on_volume(void *user, uint32_t i, vfx_volume_view *v)
{
    auto *g = static_cast<game *>(user);
    if (i != 0)
        return VFX_ERR_NOT_FOUND;
    v->point_count = 8, v->tet_count = 5;
    v->points = g->points, v->tets = g->tets, v->scalar = g->scalar;
    v->revision = 1;
    return VFX_OK;
}

void setup(game *g)
{
    // a still blob of water on the left, half behind the wall: the points of a 0.08 lattice
    // inside an ellipsoid (even spacing: a smooth surface at the default kernel radius)
    g->count = 0;
    for (int i = -9; i <= 9; ++i)
        for (int j = -7; j <= 7; ++j)
            for (int k = -7; k <= 7; ++k) {
                const float u = 0.08f * i / 0.7f, v = 0.08f * j / 0.5f, w = 0.08f * k / 0.5f;
                if (u * u + v * v + w * w > 1 || g->count == NP)
                    continue;
                g->x[g->count] = -1.8f + 0.08f * i, g->y[g->count] = -0.7f + 0.08f * j, g->z[g->count] = -0.5f + 0.08f * k;
                g->count++;
            }
    g->beam = vfx_beam{};
    g->beam.type = VFX_TYPE_BEAM;
    const float head[3] = {0.1f, 1.1f, -0.5f}, dir[3] = {-0.05f, -1, 0}, color[4] = {1.0f, 0.5f, 0.2f, 1};
    std::memcpy(g->beam.head, head, sizeof head);
    std::memcpy(g->beam.dir, dir, sizeof dir);
    std::memcpy(g->beam.color, color, sizeof color);
    g->beam.length = 2.3f, g->beam.radius = 0.4f, g->beam.a = 0.3f, g->beam.b = 0.3f, g->beam.eps = 0.03f;
    for (int i = 0; i < 8; ++i) { // a unit cube on the right, its scalar rising with height
        g->points[3 * i + 0] = 1.3f + 1.0f * static_cast<float>(i & 1);
        g->points[3 * i + 1] = -1.2f + 1.0f * static_cast<float>((i >> 1) & 1);
        g->points[3 * i + 2] = -1.0f + 1.0f * static_cast<float>((i >> 2) & 1);
        g->scalar[i] = static_cast<float>((i >> 1) & 1);
    }
    static const uint32_t t[20] = {0, 1, 2, 4, 1, 2, 3, 7, 1, 4, 5, 7, 2, 4, 6, 7, 1, 2, 4, 7};
    std::memcpy(g->tets, t, sizeof t);
}

// OGRE's GL3Plus has no fixed function: one small GLSL material per colour, Lambert-lit by
// the scene's directional light.
const char *vs_src = "#version 330 core\n"
                     "in vec4 vertex; in vec3 normal;\n"
                     "uniform mat4 wvp; uniform vec4 light_os;\n"
                     "out float lit;\n"
                     "void main() { gl_Position = wvp * vertex;\n"
                     "  lit = 0.35 + 0.65 * max(dot(normalize(normal), normalize(light_os.xyz)), 0.0); }\n";
const char *fs_src = "#version 330 core\n"
                     "in float lit; uniform vec4 colour; out vec4 frag;\n"
                     "void main() { frag = vec4(colour.rgb * lit, 1.0); }\n";

Ogre::MaterialPtr make_material(const std::string &name, const Ogre::ColourValue &c)
{
    auto &hl = Ogre::HighLevelGpuProgramManager::getSingleton();
    const auto group = Ogre::ResourceGroupManager::DEFAULT_RESOURCE_GROUP_NAME;
    if (!hl.resourceExists("lambert_vs", group)) {
        auto vs = hl.createProgram("lambert_vs", group, "glsl", Ogre::GPT_VERTEX_PROGRAM);
        vs->setSource(vs_src);
        vs->load();
        auto fs = hl.createProgram("lambert_fs", group, "glsl", Ogre::GPT_FRAGMENT_PROGRAM);
        fs->setSource(fs_src);
        fs->load();
    }
    auto m = Ogre::MaterialManager::getSingleton().create(name, group);
    Ogre::Pass *p = m->getTechnique(0)->getPass(0);
    p->setVertexProgram("lambert_vs");
    p->setFragmentProgram("lambert_fs");
    p->getVertexProgramParameters()->setNamedAutoConstant("wvp", Ogre::GpuProgramParameters::ACT_WORLDVIEWPROJ_MATRIX);
    p->getVertexProgramParameters()->setNamedAutoConstant("light_os", Ogre::GpuProgramParameters::ACT_LIGHT_POSITION_OBJECT_SPACE, 0);
    p->getFragmentProgramParameters()->setNamedConstant("colour", c);
    m->load();
    return m;
}

// A row-major Ogre::Matrix4 (column vectors) as the ABI's column-major float[16].
void to_gl(const Ogre::Matrix4 &m, float out[16])
{
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            out[4 * c + r] = static_cast<float>(m[r][c]);
}

std::vector<unsigned char> read_rgba(const Ogre::TexturePtr &t)
{
    std::vector<unsigned char> px(static_cast<size_t>(W) * H * 4);
    t->getBuffer()->blitToMemory(Ogre::PixelBox(W, H, 1, Ogre::PF_BYTE_RGBA, px.data()));
    return px;
}

bool write_ppm(const char *path, const std::vector<unsigned char> &px)
{
    FILE *f = std::fopen(path, "wb");
    if (!f)
        return false;
    std::fprintf(f, "P6 %d %d 255\n", W, H);
    for (size_t i = 0; i < px.size(); i += 4)
        std::fwrite(&px[i], 1, 3, f);
    return std::fclose(f) == 0;
}

// After OGRE has rendered its scene target: copy its colour into the output texture, then
// volfx over it, reading OGRE's colour texture and depth. Only OGRE's API and the plugin's.
struct volfx_pass : Ogre::RenderTargetListener {
    const vfx_plugin_api *api = nullptr;
    vfx_context *ctx = nullptr;
    Ogre::TexturePtr scene, output;
    Ogre::Camera *camera = nullptr;
    uint32_t scene_tex = 0, scene_fbo = 0, output_fbo = 0, effects = 0;
    double time = 0;
    bool failed = false;

    void postRenderTargetUpdate(const Ogre::RenderTargetEvent &) override
    {
        output->getBuffer()->blit(scene->getBuffer()); // blit(src): OGRE copies into output
        if (!api)
            return;
        vfx_frame_view fv{};
        fv.type = VFX_TYPE_FRAME_VIEW;
        fv.framebuffer = output_fbo;
        fv.color_texture = scene_tex;
        fv.width = W, fv.height = H;
        to_gl(camera->getViewMatrix(), fv.view);
        to_gl(camera->getProjectionMatrix(), fv.proj);
        const Ogre::Vector3 eye = camera->getDerivedPosition();
        fv.eye[0] = eye.x, fv.eye[1] = eye.y, fv.eye[2] = eye.z;
        fv.near_plane = camera->getNearClipDistance(), fv.far_plane = camera->getFarClipDistance();
        fv.fov_y = camera->getFOVy().valueRadians();
        fv.effects = effects;
        // OGRE's depth is a renderbuffer attached to its scene target's framebuffer, and OGRE's
        // render textures hold their rows top first (OGRE flips its projection for them).
        vfx_frame_depth depth{};
        depth.type = VFX_TYPE_FRAME_DEPTH;
        depth.depth_framebuffer = scene_fbo;
        depth.flip_y = 1;
        depth.depth_convention = VFX_DEPTH_STANDARD;
        fv.next = &depth;
        if (api->update(ctx, time, 1.f / 60.f) != VFX_OK || api->render(ctx, &fv) != VFX_OK) {
            std::fprintf(stderr, "volfx: %s\n", api->last_error(ctx, nullptr));
            failed = true;
        }
    }
};

// A pixel an effect is drawn on: the output differs from OGRE's scene colour by more than 32
// of 255 in a channel (the output starts each frame as an exact copy of it). Below that: the
// beams' bloom, a screen-space halo around the visible beam that reaches up to 19 levels over
// the wall next to it at this size; an effect's own pixels differ by more.
bool drawn(const std::vector<unsigned char> &a, const std::vector<unsigned char> &b, size_t p)
{
    for (size_t c = 4 * p; c < 4 * p + 3; ++c)
        if (std::abs(a[c] - b[c]) > 32)
            return true;
    return false;
}

// A pixel OGRE's own image changed between two shots.
bool changed(const std::vector<unsigned char> &a, const std::vector<unsigned char> &b, size_t p)
{
    return a[4 * p] != b[4 * p] || a[4 * p + 1] != b[4 * p + 1] || a[4 * p + 2] != b[4 * p + 2];
}

struct shot {
    std::vector<unsigned char> scene, out;
};

// Two frames with only `effects` drawn (the volume clips against the previous frame's depth, so
// the second frame is the first whose depth history is this state's), OGRE's scene held still.
shot render_still(Ogre::Root *root, volfx_pass &pass, uint32_t effects)
{
    pass.effects = effects;
    for (int i = 0; i < 2; ++i) {
        pass.time += 1 / 60.0;
        root->renderOneFrame();
    }
    return shot{read_rgba(pass.scene), read_rgba(pass.output)};
}

// Check 1: each effect is drawn where OGRE's depth lets it be. Rendered alone, with the wall
// hidden it covers pixels where the wall stands (so the wall is in front of part of it), with
// the wall shown it covers none of them, and it covers pixels elsewhere (in front of the floor
// and the sky). The wall's pixels are where OGRE's own image changes when it is hidden, less a
// 2-pixel border (where OGRE's edge and the effects' screen-space glow may meet).
bool check_depth(Ogre::Root *root, volfx_pass &pass, Ogre::SceneNode *wall, uint32_t built)
{
    static const char *names[3] = {"water", "beams", "volume"};
    const size_t n = static_cast<size_t>(W) * H;
    std::vector<char> wall_px(n, 0), core(n, 0);
    bool ok = !pass.failed;
    for (int e = 0; e < 3; ++e) {
        if (!(built & VFX_EFFECT_BIT(e)))
            continue;
        wall->setVisible(true);
        shot shown = render_still(root, pass, VFX_EFFECT_BIT(e));
        wall->setVisible(false);
        shot hidden = render_still(root, pass, VFX_EFFECT_BIT(e));
        wall->setVisible(true);
        if (pass.failed)
            return false;
        size_t wall_count = 0;
        for (size_t p = 0; p < n; ++p)
            wall_count += wall_px[p] = changed(shown.scene, hidden.scene, p);
        for (int y = 2; y < H - 2; ++y)
            for (int x = 2; x < W - 2; ++x) {
                bool all = true;
                for (int dy = -2; dy <= 2 && all; ++dy)
                    for (int dx = -2; dx <= 2 && all; ++dx)
                        all = wall_px[static_cast<size_t>((y + dy) * W + x + dx)];
                core[static_cast<size_t>(y * W + x)] = all;
            }
        size_t front = 0, behind = 0, leaked = 0;
        int halo = 0; // the largest change over the wall's pixels when it is shown
        for (size_t p = 0; p < n; ++p) {
            for (size_t c = 4 * p; core[p] && c < 4 * p + 3; ++c)
                halo = std::max(halo, std::abs(shown.out[c] - shown.scene[c]));
            front += !wall_px[p] && drawn(shown.out, shown.scene, p);
            behind += core[p] && drawn(hidden.out, hidden.scene, p);
            leaked += core[p] && drawn(shown.out, shown.scene, p);
        }
        if (const char *dir = std::getenv("VFX_OGRE_DEBUG")) {
            std::string base = std::string(dir) + "/" + names[e];
            write_ppm((base + "_shown.ppm").c_str(), shown.out);
            write_ppm((base + "_hidden.ppm").c_str(), hidden.out);
            write_ppm((base + "_scene.ppm").c_str(), shown.scene);
        }
        std::printf("%-6s: %zu px in front of OGRE's scene, %zu px where the wall stands when it is hidden, "
                    "%zu px through the wall (%zu wall px, at most %d levels changed on them)\n", names[e], front, behind,
                    leaked, wall_count, halo);
        ok = ok && front >= 100 && behind >= 100 && leaked == 0 && wall_count > 1000;
    }
    return ok;
}

} // namespace

int main(int argc, char **argv)
{
    bool use_volfx = true, skip_restore = false, depth_check = true;
    int frames = 30;
    const char *target_ppm = nullptr, *output_ppm = nullptr;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--no-volfx")) use_volfx = false;
        else if (!std::strcmp(argv[i], "--skip-restore")) skip_restore = true;
        else if (!std::strcmp(argv[i], "--no-depth-check")) depth_check = false;
        else if (!std::strcmp(argv[i], "--frames") && i + 1 < argc) frames = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--target") && i + 1 < argc) target_ppm = argv[++i];
        else if (!std::strcmp(argv[i], "--output") && i + 1 < argc) output_ppm = argv[++i];
        else {
            std::fprintf(stderr, "ogre_host: unknown argument %s\n", argv[i]);
            return 2;
        }
    }
    // OGRE's log to stderr only when asked (VFX_OGRE_LOG=1), no Ogre.log file.
    const double t0 = now_s();
    auto *logs = new Ogre::LogManager();
    logs->createLog("ogre_host", true, std::getenv("VFX_OGRE_LOG") != nullptr, true);
    auto *root = new Ogre::Root("", "", "");
    Ogre::RenderWindow *window = nullptr;
    try {
        root->loadPlugin(OGRE_PLUGIN_DIR "/RenderSystem_GL3Plus");
        root->setRenderSystem(root->getRenderSystemByName("OpenGL 3+ Rendering Subsystem"));
        root->initialise(false);
        Ogre::NameValuePairList misc{{"hidden", "true"}};
        window = root->createRenderWindow("volfx in OGRE", W, H, false, &misc);
    } catch (const Ogre::Exception &e) {
        // Root is not deleted: OGRE 1.12's destructor crashes after a failed GLX window.
        std::fprintf(stderr, "OGRE: no GL3Plus window (%s): skipping\n", e.getFullDescription().c_str());
        return 77;
    }
    window->setAutoUpdated(false);
    const double t_window = now_s();
    auto &caps = *root->getRenderSystem()->getCapabilities();
    std::printf("OGRE %d.%d.%d, %s, driver %s\n", OGRE_VERSION_MAJOR, OGRE_VERSION_MINOR, OGRE_VERSION_PATCH,
                root->getRenderSystem()->getName().c_str(), caps.getDeviceName().c_str());
    Ogre::ResourceGroupManager::getSingleton().initialiseAllResourceGroups();

    // The scene: a floor, a wall in front of the effects, a spinning cube, a directional light.
    Ogre::SceneManager *sm = root->createSceneManager();
    Ogre::Light *sun = sm->createLight("sun");
    sun->setType(Ogre::Light::LT_DIRECTIONAL);
    Ogre::SceneNode *sun_node = sm->getRootSceneNode()->createChildSceneNode();
    sun_node->attachObject(sun);
    sun_node->setDirection(Ogre::Vector3(-0.4f, -1, -0.6f), Ogre::Node::TS_WORLD);
    Ogre::MeshManager::getSingleton().createPlane("floor", Ogre::ResourceGroupManager::DEFAULT_RESOURCE_GROUP_NAME,
                                                 Ogre::Plane(Ogre::Vector3::UNIT_Y, -1.2f), 30, 30, 1, 1, true, 1, 1, 1,
                                                 Ogre::Vector3::UNIT_Z);
    Ogre::Entity *floor = sm->createEntity("floor");
    floor->setMaterial(make_material("floor_mat", Ogre::ColourValue(0.55f, 0.5f, 0.42f)));
    sm->getRootSceneNode()->attachObject(floor);
    // OGRE's prefab cube is 100 units: the wall spans x -2.8..2.8, y -1.2..-0.45, z 1.1..1.3
    Ogre::Entity *wall = sm->createEntity(Ogre::SceneManager::PT_CUBE);
    wall->setMaterial(make_material("wall_mat", Ogre::ColourValue(0.7f, 0.2f, 0.15f)));
    Ogre::SceneNode *wall_node = sm->getRootSceneNode()->createChildSceneNode(Ogre::Vector3(0, -0.825f, 1.2f));
    wall_node->setScale(0.056f, 0.0075f, 0.002f);
    wall_node->attachObject(wall);
    Ogre::Entity *spinner = sm->createEntity(Ogre::SceneManager::PT_CUBE);
    spinner->setMaterial(make_material("spinner_mat", Ogre::ColourValue(0.2f, 0.6f, 0.25f)));
    Ogre::SceneNode *spinner_node = sm->getRootSceneNode()->createChildSceneNode(Ogre::Vector3(-2.6f, 1.3f, -1.5f));
    spinner_node->setScale(0.006f, 0.006f, 0.006f);
    spinner_node->attachObject(spinner);

    Ogre::Camera *camera = sm->createCamera("camera");
    camera->setNearClipDistance(0.1f);
    camera->setFarClipDistance(60);
    camera->setFOVy(Ogre::Radian(0.96f));
    camera->setAspectRatio(static_cast<Ogre::Real>(W) / H);
    Ogre::SceneNode *cam_node = sm->getRootSceneNode()->createChildSceneNode(Ogre::Vector3(0, 0.6f, 5));
    cam_node->lookAt(Ogre::Vector3(0, -0.2f, 0), Ogre::Node::TS_WORLD);
    cam_node->attachObject(camera);

    // OGRE's scene target (RGBA8 colour texture, OGRE's depth renderbuffer from its pool) and the
    // output the effects are composited into (no depth of its own).
    const auto group = Ogre::ResourceGroupManager::DEFAULT_RESOURCE_GROUP_NAME;
    Ogre::TexturePtr scene = Ogre::TextureManager::getSingleton().createManual(
        "scene", group, Ogre::TEX_TYPE_2D, W, H, 0, Ogre::PF_BYTE_RGBA, Ogre::TU_RENDERTARGET);
    Ogre::TexturePtr output = Ogre::TextureManager::getSingleton().createManual(
        "volfx_output", group, Ogre::TEX_TYPE_2D, W, H, 0, Ogre::PF_BYTE_RGBA, Ogre::TU_RENDERTARGET);
    Ogre::RenderTarget *scene_rt = scene->getBuffer()->getRenderTarget();
    Ogre::Viewport *vp = scene_rt->addViewport(camera);
    vp->setBackgroundColour(Ogre::ColourValue(0.30f, 0.36f, 0.44f));
    vp->setClearEveryFrame(true);
    Ogre::RenderTarget *output_rt = output->getBuffer()->getRenderTarget();
    output_rt->setAutoUpdated(false);
    output_rt->setDepthBufferPool(Ogre::DepthBuffer::POOL_NO_DEPTH);

    static game g;
    setup(&g);
    volfx_pass pass;
    pass.scene = scene, pass.output = output, pass.camera = camera;
    vfx_plugin_api api{};
    api.type = VFX_TYPE_PLUGIN_API;
    if (use_volfx) {
        vfx_gl_state_desc gl_state{};
        gl_state.type = VFX_TYPE_GL_STATE_DESC;
        gl_state.skip_restore = skip_restore ? 1 : 0;
        vfx_context_desc host{};
        host.type = VFX_TYPE_CONTEXT_DESC;
        host.next = &gl_state;
        host.user = &g;
        host.gl_get_proc_address = on_proc, host.log = on_log;
        host.particle_chunk_count = on_chunks, host.particle_chunk = on_chunk, host.water_params = on_water;
        host.beams = on_beams, host.volume_count = on_volumes, host.volume = on_volume;
        // OGRE's depth needs vfx_frame_depth (ABI 1.1), which a 1.0 plugin would skip and then
        // draw against no depth, upside down: ask the plugin first.
        vfx_plugin_info info{};
        info.type = VFX_TYPE_PLUGIN_INFO;
        api.next = &info;
        if (vfx_plugin_entry(VFX_ABI_VERSION, &host, &api) != VFX_OK) {
            std::fprintf(stderr, "volfx: plugin entry refused\n");
            return 1;
        }
        if (!(info.known_types & (1ull << VFX_TYPE_FRAME_DEPTH))) {
            std::fprintf(stderr, "volfx: the plugin (ABI 1.%u) does not read vfx_frame_depth\n", info.abi_minor);
            return 1;
        }
        if (api.create(&host, &pass.ctx) != VFX_OK) {
            std::fprintf(stderr, "volfx: %s\n", pass.ctx ? api.last_error(pass.ctx, nullptr) : "create failed");
            return 1;
        }
        pass.api = &api;
        scene->getCustomAttribute("GLID", &pass.scene_tex);
        scene_rt->getCustomAttribute("GL_FBOID", &pass.scene_fbo);
        output_rt->getCustomAttribute("GL_FBOID", &pass.output_fbo);
    }
    scene_rt->addListener(&pass);

    const double t_setup = now_s();
    int rc = 0;
    for (int frame = 0; frame <= frames && !pass.failed; ++frame) {
        spinner_node->setOrientation(Ogre::Quaternion(Ogre::Radian(0.1f * frame), Ogre::Vector3(0.3f, 1, 0.2f).normalisedCopy()));
        pass.time = frame / 60.0;
        root->renderOneFrame();
    }
    const double t_frames = now_s();
    std::printf("times: OGRE window %.2f s, scene and volfx create %.2f s, %d frames %.2f s\n", t_window - t0,
                t_setup - t_window, frames + 1, t_frames - t_setup);
    if (pass.failed || g.errors)
        rc = 1;
    if (target_ppm && !write_ppm(target_ppm, read_rgba(scene)))
        rc = 1;
    if (output_ppm && !write_ppm(output_ppm, read_rgba(output)))
        rc = 1;
    if (use_volfx && depth_check && rc == 0 && !check_depth(root, pass, wall_node, api.effects_built)) {
        std::fprintf(stderr, "ogre_host: an effect is not drawn where OGRE's depth lets it be\n");
        rc = 1;
    }
    if (pass.ctx)
        api.destroy(pass.ctx);
    pass.scene.reset(), pass.output.reset(), scene.reset(), output.reset(); // before OGRE goes
    delete root;
    delete logs;
    return rc;
}
