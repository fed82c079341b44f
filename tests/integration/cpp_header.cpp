// cpp_header.cpp — volfx.h in a C++17 (and a C++20) translation unit (-Wall -Wextra -Werror): aggregates are
// value-initialized and filled field by field, as a C++17 engine would; nothing is called.
#include <volfx/volfx.h>

int main()
{
    vfx_beam b{};
    b.type = VFX_TYPE_BEAM;
    b.radius = 0.5f;
    vfx_beams_view v{};
    v.type = VFX_TYPE_BEAMS_VIEW;
    v.count = 1;
    v.beams = &b;
    vfx_frame_view f{};
    f.type = VFX_TYPE_FRAME_VIEW;
    vfx_plugin_api api{};
    api.type = VFX_TYPE_PLUGIN_API;
    vfx_plugin_entry_fn entry = vfx_plugin_entry;
    return (entry != nullptr && v.beams->radius > 0 && f.width == 0 && api.type == VFX_TYPE_PLUGIN_API
            && vfx_result_name(VFX_OK)[0] == 'o') ? 0 : 1;
}
