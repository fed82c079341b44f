// PBF scatter: each particle to its sorted row start[cell] + its slot in the cell; the predicted
// position, velocity and id move with it (the state is kept in cell order, as the CPU solver
// reorders its rows at every rebuild).
#include "sim/pbf_common.glsl"
layout(std430, binding = 0) readonly buffer Pos { vec4 pos[]; };
layout(std430, binding = 2) readonly buffer Vel { vec4 vel[]; };
layout(std430, binding = 3) readonly buffer Key { uvec2 key[]; };
layout(std430, binding = 4) readonly buffer Id { uint id[]; };
layout(std430, binding = 5) writeonly buffer OutPos { vec4 out_pos[]; };
layout(std430, binding = 6) writeonly buffer OutVel { vec4 out_vel[]; };
layout(std430, binding = 7) writeonly buffer OutId { uint out_id[]; };

void main()
{
    uint i = gl_GlobalInvocationID.x;
    if (i >= PBF_N)
        return;
    uvec2 k = key[i];
    uint dst = start[k.x] + k.y;
    out_pos[dst] = pos[i];
    out_vel[dst] = vel[i];
    out_id[dst] = id[i];
}
