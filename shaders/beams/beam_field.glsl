// beam_field.glsl — the closed-form beam integral, line for line the float path of
// plugin/lab/beam_field_impl.inc (docs/beams.md has the derivation). Positions are relative
// to the eye, so the ray origin is 0 and far beams keep their digits.

const float VOLFX_BEAM_EPS_FLOOR = 1e-6;

// a*b - c*d with one rounding (Kahan); `precise` stops the compiler from re-fusing it.
float volfx_dop(float a, float b, float c, float d)
{
    precise float w = c * d;
    precise float e = fma(-c, d, w);
    precise float f = fma(a, b, -w);
    return f + e;
}

vec3 volfx_cross_acc(vec3 a, vec3 b)
{
    return vec3(volfx_dop(a.y, b.z, a.z, b.y), volfx_dop(a.z, b.x, a.x, b.z), volfx_dop(a.x, b.y, a.y, b.x));
}

// log1p(z)/z, z >= 0: log() near 1 is only 2^-21 absolute in GLSL, so a series below 0.1.
float volfx_log1p_over(float z)
{
    if (z < 0.1) {
        float s = 0.1;
        for (int n = 9; n >= 1; --n)
            s = 1.0 / float(n) - z * s;
        return s;
    }
    return log(1.0 + z) / z;
}

float volfx_same_sign(float lo, float hi, float dx, float s, float Q)
{
    float S0 = sqrt(lo * lo + Q * Q), S1 = sqrt(hi * hi + Q * Q);
    float k = 1.0 + (hi + lo) / (S1 + S0);
    float den = lo + S0;
    float z = s * dx * k / den;
    return dx * k / den * volfx_log1p_over(z);
}

// The same-sign pieces of [y0, y1] (beam_field_impl.inc's branches as selects): split at 0 when
// the signs differ, mirrored when both are negative; the second piece is empty (lo = hi = dx = 0,
// which the piece functions turn into exactly 0) unless split. llvmpipe executes every branch
// of an `if` for all lanes, so one call site per piece instead of four halves the piece code a
// pixel runs; the values and their sum are the same to the bit.
void volfx_same_sign_parts(float dx, float y0, float y1, out vec3 p0, out vec3 p1)
{
    if (y0 < 0.0 && y1 > 0.0) {
        float xa = dx * (-y0) / (y1 - y0);
        p0 = vec3(0.0, -y0, xa);
        p1 = vec3(0.0, y1, dx - xa);
    } else {
        p0 = y1 <= 0.0 ? vec3(-y1, -y0, dx) : vec3(y0, y1, dx);
        p1 = vec3(0.0);
    }
}

// integral over x in [x0, x1] of 1/sqrt((s x + beta)^2 + Q^2)
float volfx_segment_integral(float x0, float x1, float s, float beta, float Q)
{
    float dx = x1 - x0;
    if (!(dx > 0.0) || !(Q > 0.0))
        return 0.0;
    vec3 p0, p1;
    volfx_same_sign_parts(dx, s * x0 + beta, s * x1 + beta, p0, p1);
    return volfx_same_sign(p0.x, p0.y, p0.z, s, Q) + volfx_same_sign(p1.x, p1.y, p1.z, s, Q);
}

#ifdef VOLFX_BEAMS_SMOOTH
// the smooth support's piece (beam_field_impl.inc smooth_same_sign): 0 <= lo <= hi <= h, units
// of R; edge series near the support edge, binomial series when grazing, closed form elsewhere
const int VOLFX_EDGE_TERMS = 12;
const int VOLFX_SERIES_TERMS = 12;
const float VOLFX_GRAZING_M = 0.25; // as the float path of beam_field_impl.inc
float volfx_smooth_same_sign(float lo, float hi, float dx, float s, float Q, float h)
{
    hi = min(hi, h);
    lo = min(lo, hi);
    float Q2 = Q * Q, h2 = h * h, rho = sqrt(h2 + Q2);
    if (4.0 * (h - lo) <= rho) {
        float x = h / rho, zl = (h - lo) / rho, zh = (h - hi) / rho;
        float e3 = zl * zl + zl * zh + zh * zh, pw = zh * zh * zh;
        float e4 = zl * e3 + pw;
        pw *= zh;
        float e5 = zl * e4 + pw;
        pw *= zh;
        float P = 1.0, Pm = 0.0, sum = 0.0;
        for (int n = 0; n < VOLFX_EDGE_TERMS; ++n) {
            float k = float(n + 3);
            sum += P * (4.0 * x * x * e3 / k - 4.0 * x * e4 / (k + 1.0) + e5 / (k + 2.0));
            e3 = e4;
            e4 = e5;
            e5 = zl * e5 + pw;
            pw *= zh;
            float Pn = (float(2 * n + 1) * x * P - float(n) * Pm) / float(n + 1);
            Pm = P;
            P = Pn;
        }
        return dx * rho * rho * rho * sum;
    }
    if (h2 < VOLFX_GRAZING_M * Q2) {
        float u0 = lo / h, u1 = hi / h, m = h2 / Q2;
        float E0 = 1.0, P = u0, u11 = u1 * u1, us = u1 + u0, u00 = u0 * u0;
        float E1 = u11 * E0 + P * us;
        P *= u00;
        float E2 = u11 * E1 + P * us;
        P *= u00;
        float c = 1.0, mn = 1.0, sum = 0.0;
        for (int n = 0; n < VOLFX_SERIES_TERMS; ++n) {
            float k = float(2 * n + 1);
            sum += c * mn * (E0 / k - 2.0 * E1 / (k + 2.0) + E2 / (k + 4.0));
            E0 = E1;
            E1 = E2;
            E2 = u11 * E1 + P * us;
            P *= u00;
            c *= -float(2 * n + 1) / float(2 * n + 2);
            mn *= m;
        }
        return h2 * h2 * dx / Q * sum;
    }
    float c0 = h2 * h2 + h2 * Q2 + 0.375 * Q2 * Q2, kappa = h2 + 0.375 * Q2;
    float S0 = sqrt(lo * lo + Q2), S1 = sqrt(hi * hi + Q2);
    float dT = S1 + lo * (hi + lo) / (S1 + S0);
    float g = dT * (hi * hi * 0.25 - kappa) + lo * S0 * (hi + lo) * 0.25;
    return c0 * volfx_same_sign(lo, hi, dx, s, Q) + dx * g;
}

float volfx_segment_integral_smooth(float x0, float x1, float s, float beta, float Q, float h)
{
    float dx = x1 - x0;
    if (!(dx > 0.0) || !(Q > 0.0) || !(h > 0.0))
        return 0.0;
    vec3 p0, p1;
    volfx_same_sign_parts(dx, s * x0 + beta, s * x1 + beta, p0, p1);
    return volfx_smooth_same_sign(p0.x, p0.y, p0.z, s, Q, h) + volfx_smooth_same_sign(p1.x, p1.y, p1.z, s, Q, h);
}

#endif

// The smooth and polyline code is compiled in only when a beam of the frame needs it
// (VOLFX_BEAMS_SMOOTH, VOLFX_BEAMS_POLYLINE): llvmpipe pays for code a lane skips.
float volfx_piece(float x0, float x1, float s, float beta, float Q, float h, float R, bool soft)
{
#ifdef VOLFX_BEAMS_SMOOTH
    if (soft) {
        float ir = 1.0 / R;
        return volfx_segment_integral_smooth(x0, x1, s * ir, beta * ir, Q * ir, h * ir) * ir;
    }
#endif
    return volfx_segment_integral(x0, x1, s, beta, Q);
}

// restricts [lo, hi] to u0 + c x in [umin, umax) (half-open: a ray in a boundary plane counts once)
void volfx_clip_linear(float u0, float c, float umin, float umax, inout float lo, inout float hi)
{
    if (c == 0.0) {
        if (u0 < umin || u0 >= umax)
            hi = lo - 1.0;
        return;
    }
    float a = (umin - u0) / c, b = (umax - u0) / c;
    if (c < 0.0) {
        float t = a;
        a = b;
        b = t;
    }
    lo = max(lo, a);
    hi = min(hi, b);
}

float volfx_sphere_piece(vec3 g, vec3 V, float R, float eps, float ta, float tb, float u0, float c,
                       float umin, float umax, bool soft)
{
    float gv = dot(g, V);
    vec3 gp = g - gv * V;
    float dd = dot(gp, gp);
    if (dd >= R * R)
        return 0.0;
    float h = sqrt(R * R - dd);
    float lo = ta, hi = tb;
    volfx_clip_linear(u0, c, umin, umax, lo, hi);
    float slo = max(lo + gv, -h), shi = min(hi + gv, h);
    return volfx_piece(slo, shi, 1.0, 0.0, sqrt(dd + eps * eps), h, R, soft);
}

float volfx_cylinder_piece(vec3 wp, vec3 V, vec3 D, float L, float R, float eps, float ta, float tb,
                         float u0, float c, bool soft)
{
    float wd = dot(wp, D);
    vec3 a = wp - wd * D;
    vec3 b = volfx_cross_acc(volfx_cross_acc(D, V), D);
    float s = sqrt(dot(b, b));
    float beta = 0.0, rr, hc, lo = ta, hi = tb;
    if (s > 0.0) {
        vec3 bh = b / s;
        beta = dot(a, bh);
        vec3 q = a - beta * bh;
        rr = dot(q, q);
        if (rr >= R * R)
            return 0.0;
        hc = sqrt(R * R - rr);
        volfx_clip_linear(beta, s, -hc, hc, lo, hi);
    } else {
        rr = dot(a, a);
        if (rr > R * R)
            return 0.0;
        hc = sqrt(R * R - rr);
    }
    volfx_clip_linear(u0, c, 0.0, L, lo, hi);
    return volfx_piece(lo, hi, s, beta, sqrt(rr + eps * eps), hc, R, soft);
}

// The ray seen from M: P(tau) - M = wp + tau V with tau measured from the closest approach to M
// ([ta, tb] the ray's [t0, t1]), and u(tau) = u0 + c tau along D.
vec3 volfx_ray_frame(vec3 M, vec3 D, vec3 V, float t0, float t1, out float ta, out float tb, out float c,
                     out float u0)
{
    vec3 w = -M;
    vec3 wp = volfx_cross_acc(V, volfx_cross_acc(w, V));
    float wv = dot(w, V);
    ta = t0 + wv, tb = t1 + wv;
    c = dot(V, D), u0 = dot(wp, D);
    return wp;
}

// H of one beam along t*V (origin = eye = 0), t in [t0, t1]; M is relative to the eye.
float volfx_beam_integral(vec3 M, vec3 D, float L, float R, float a, float b, float eps_in, bool soft,
                        vec3 V, float t0, float t1)
{
    if (!(t1 > t0))
        return 0.0;
    float eps = max(eps_in, VOLFX_BEAM_EPS_FLOOR * R), ta, tb, c, u0;
    vec3 wp = volfx_ray_frame(M, D, V, t0, t1, ta, tb, c, u0);
    float H = 0.0;
    if (a > 0.0)
        H += a * volfx_sphere_piece(wp, V, R, eps, ta, tb, 0.0, 0.0, -1.0, 1.0, soft);
    if (b > 0.0) {
        const float inf = 1e30;
        H += b * volfx_sphere_piece(wp, V, R, eps, ta, tb, u0, c, -inf, 0.0, soft);
        H += b * volfx_cylinder_piece(wp, V, D, L, R, eps, ta, tb, u0, c, soft);
        H += b * volfx_sphere_piece(wp - L * D, V, R, eps, ta, tb, u0, c, L, inf, soft);
    }
    return H;
}

#ifdef VOLFX_BEAMS_ANATOMY
// beam_field_impl.inc's anatomy, line for line: an0 = (head radius (0 -> R), orb radius, orb
// strength, 0), an1 = (taper, surge, 1 / surge wavelength, surge phase).
float volfx_profile(vec4 an1, float L, float u)
{
    float f = 1.0;
    if (an1.x > 0.0 && L > 0.0)
        f *= 1.0 - an1.x * clamp(u / L, 0.0, 1.0);
    if (an1.y > 0.0) {
        float x = u * an1.z + an1.w;
        float cb = 0.5 + 0.5 * cos(6.283185307179586 * (x - floor(x)));
        f *= 1.0 + an1.y * cb * cb * cb;
    }
    return f;
}

float volfx_trail_profiled(vec3 wp, vec3 V, vec3 D, float L, float R, vec4 an1, float eps, float ta, float tb,
                           float u0, float c, bool soft)
{
    const float inf = 1e30;
    float H = volfx_sphere_piece(wp, V, R * volfx_profile(an1, L, 0.0), eps, ta, tb, u0, c, -inf, 0.0, soft)
              + volfx_sphere_piece(wp - L * D, V, R * volfx_profile(an1, L, L), eps, ta, tb, u0, c, L, inf, soft);
    float Rm = R * (1.0 + an1.y);
    float wd = dot(wp, D);
    vec3 a = wp - wd * D;
    vec3 b = volfx_cross_acc(volfx_cross_acc(D, V), D);
    float s = sqrt(dot(b, b)), lo = ta, hi = tb;
    if (s > 0.0) {
        vec3 bh = b / s;
        float beta = dot(a, bh);
        vec3 q = a - beta * bh;
        float rr = dot(q, q);
        if (rr >= Rm * Rm)
            return H;
        float hc = sqrt(Rm * Rm - rr);
        volfx_clip_linear(beta, s, -hc, hc, lo, hi);
    } else if (dot(a, a) > Rm * Rm) {
        return H;
    }
    volfx_clip_linear(u0, c, 0.0, L, lo, hi);
    if (!(hi >= lo))
        return H;
    float ua = u0 + c * lo, ub = u0 + c * hi;
    if (ua > ub) {
        float t = ua;
        ua = ub, ub = t;
    }
    ua = max(ua, 0.0), ub = min(ub, L);
    float step = inf;
    if (an1.y > 0.0)
        step = 1.0 / (16.0 * an1.z);
    if (an1.x > 0.0 && L / 8.0 < step)
        step = L / 8.0;
    float span = ub - ua;
    int n = span > step ? int(span / step) + 1 : 1;
    n = min(n, 16);
    if (n == 1)
        return H + volfx_cylinder_piece(wp, V, D, L, R * volfx_profile(an1, L, 0.5 * (ua + ub)), eps, ta, tb, u0, c,
                                        soft);
    float du = span / float(n);
    for (int k = 0; k < n; ++k) {
        float ulo = k == 0 ? 0.0 : ua + float(k) * du, uhi = k == n - 1 ? L : ua + float(k + 1) * du;
        float um = ua + (float(k) + 0.5) * du;
        H += volfx_cylinder_piece(wp - ulo * D, V, D, uhi - ulo, R * volfx_profile(an1, L, um), eps, ta, tb, u0 - ulo,
                                  c, soft);
    }
    return H;
}

float volfx_beam_integral_anat(vec3 M, vec3 D, float L, float R, float a, float b, float eps_in, bool soft,
                               vec4 an0, vec4 an1, vec3 V, float t0, float t1)
{
    if (!(t1 > t0))
        return 0.0;
    float eps = max(eps_in, VOLFX_BEAM_EPS_FLOOR * R), ta, tb, c, u0;
    vec3 wp = volfx_ray_frame(M, D, V, t0, t1, ta, tb, c, u0);
    vec3 ge = wp - L * D;
    float H = 0.0;
    const float inf = 1e30;
    if (a > 0.0)
        H += a * volfx_sphere_piece(wp, V, an0.x > 0.0 ? an0.x : R, eps, ta, tb, 0.0, 0.0, -1.0, 1.0, soft);
    if (an0.y > 0.0 && an0.z > 0.0)
        H += an0.z * volfx_sphere_piece(ge, V, an0.y, eps, ta, tb, 0.0, 0.0, -1.0, 1.0, soft);
    if (!(b > 0.0))
        return H;
    if (an1.x > 0.0 || an1.y > 0.0)
        return H + b * volfx_trail_profiled(wp, V, D, L, R, an1, eps, ta, tb, u0, c, soft);
    H += b * volfx_sphere_piece(wp, V, R, eps, ta, tb, u0, c, -inf, 0.0, soft);
    H += b * volfx_cylinder_piece(wp, V, D, L, R, eps, ta, tb, u0, c, soft);
    H += b * volfx_sphere_piece(ge, V, R, eps, ta, tb, u0, c, L, inf, soft);
    return H;
}
#endif

// ---------------------------------------------------------------- bending beams (polylines)
// beam_field_impl.inc polyline_integral, line for line: the nearest primitive (joint or segment
// interior) per interval between switch points. The includer defines
// `vec3 volfx_joint(uint i)` (the i-th joint, relative to the eye) before including this file
// with VOLFX_BEAMS_POLYLINE.
#ifdef VOLFX_BEAMS_POLYLINE
const int VOLFX_BEAM_MAX_JOINTS = 6;
const int VOLFX_POLY_MAX_PRIMS = 2 * VOLFX_BEAM_MAX_JOINTS - 1;
const int VOLFX_POLY_MAX_BREAKS = VOLFX_POLY_MAX_PRIMS * (VOLFX_POLY_MAX_PRIMS - 1) + 2 * VOLFX_BEAM_MAX_JOINTS + 2;

vec3 volfx_prim_quad(vec3 V, vec3 C, vec3 D, bool seg)
{
    vec3 w = -C;
    if (!seg)
        return vec3(dot(V, V), dot(w, V), dot(w, w));
    vec3 vx = volfx_cross_acc(V, D), wx = volfx_cross_acc(w, D);
    return vec3(dot(vx, vx), dot(wx, vx), dot(wx, wx));
}

float volfx_prim_dist2(vec3 V, vec3 C, vec3 D, float L, bool seg, float t)
{
    vec3 p = t * V - C;
    if (!seg)
        return dot(p, p);
    float u = dot(p, D);
    if (u < 0.0 || u > L)
        return 1e30;
    vec3 q = p - u * D;
    return dot(q, q);
}

// A joint's sphere or a segment's cylinder: volfx_sphere_piece's and volfx_cylinder_piece's
// arguments to volfx_piece computed side by side and chosen by selects, then one volfx_piece.
// llvmpipe runs both sides of an `if` for all lanes, so the branch form paid two piece
// evaluations per run; the values are the same to the bit (beam_field_impl.inc keeps the branch,
// which a CPU takes).
float volfx_prim_piece(vec3 V, vec3 C, vec3 D, float L, bool seg, float R, float eps, float ta, float tb, bool soft)
{
    vec3 w = -C;
    vec3 wp = volfx_cross_acc(V, volfx_cross_acc(w, V));
    float wv = dot(w, V);
    ta += wv;
    tb += wv;
    // the joint's sphere (volfx_sphere_piece with u0 = c = 0, [umin, umax) = [-1, 1): no clip)
    float gv = dot(wp, V);
    vec3 gp = wp - gv * V;
    float dd = dot(gp, gp);
    bool sph_in = dd < R * R;
    float hs = sqrt(max(R * R - dd, 0.0));
    float slo = max(ta + gv, -hs), shi = min(tb + gv, hs);
    // the segment's cylinder (volfx_cylinder_piece)
    float u0 = dot(wp, D), c = dot(V, D);
    vec3 a = wp - u0 * D;
    vec3 b = volfx_cross_acc(volfx_cross_acc(D, V), D);
    float s = sqrt(dot(b, b));
    float beta = 0.0, rr, lo = ta, hi = tb;
    bool cin;
    if (s > 0.0) {
        vec3 bh = b / s;
        beta = dot(a, bh);
        vec3 q = a - beta * bh;
        rr = dot(q, q);
        cin = rr < R * R;
    } else {
        rr = dot(a, a);
        cin = rr <= R * R;
    }
    float hc = sqrt(max(R * R - rr, 0.0));
    if (s > 0.0)
        volfx_clip_linear(beta, s, -hc, hc, lo, hi);
    volfx_clip_linear(u0, c, 0.0, L, lo, hi);
    bool inside = seg ? cin : sph_in;
    float x0 = seg ? lo : slo, x1 = seg ? hi : shi;
    return volfx_piece(x0, inside ? x1 : x0, seg ? s : 1.0, seg ? beta : 0.0, sqrt((seg ? rr : dd) + eps * eps),
                       seg ? hc : hs, R, soft);
}

float volfx_polyline_integral(uint first, int nj, float R, float a, float b, float eps_in, bool soft, vec3 V,
                              float t0, float t1)
{
    if (!(t1 > t0) || nj < 1)
        return 0.0;
    float eps = max(eps_in, VOLFX_BEAM_EPS_FLOOR * R);
    float H = a > 0.0 ? a * volfx_prim_piece(V, volfx_joint(first), vec3(0.0), 0.0, false, R, eps, t0, t1, soft) : 0.0;
    if (!(b > 0.0))
        return H;
    vec3 C[VOLFX_POLY_MAX_PRIMS], D[VOLFX_POLY_MAX_PRIMS], Q[VOLFX_POLY_MAX_PRIMS];
    float L[VOLFX_POLY_MAX_PRIMS];
    bool seg[VOLFX_POLY_MAX_PRIMS];
    int m = 0;
    for (int k = 0; k < 2 * nj - 1; ++k) {
        int j = k < nj ? k : k - nj;
        bool s = k >= nj;
        vec3 Cj = volfx_joint(first + uint(j)), d = vec3(0.0);
        float len = 0.0;
        if (s) {
            d = volfx_joint(first + uint(j + 1)) - Cj;
            len = sqrt(dot(d, d));
            if (!(len > 0.0))
                continue;
            d /= len;
        }
        vec3 q = volfx_prim_quad(V, Cj, d, s);
        float dmin = q.x > 0.0 ? q.z - q.y * q.y / q.x : q.z;
        if (dmin > R * R)
            continue;
        C[m] = Cj;
        D[m] = d;
        Q[m] = q;
        L[m] = len;
        seg[m] = s;
        m++;
    }
    if (m == 0)
        return H;
    float br[VOLFX_POLY_MAX_BREAKS];
    int nb = 0;
    br[nb++] = t0;
    br[nb++] = t1;
    for (int i = 0; i < m; ++i) {
        if (seg[i]) {
            float c = dot(V, D[i]), u0 = dot(-C[i], D[i]);
            if (c != 0.0) {
                float ta = -u0 / c, tb = (L[i] - u0) / c;
                if (ta > t0 && ta < t1) br[nb++] = ta;
                if (tb > t0 && tb < t1) br[nb++] = tb;
            }
        }
        for (int j = i + 1; j < m; ++j) {
            float A = Q[i].x - Q[j].x, B = Q[i].y - Q[j].y, G = Q[i].z - Q[j].z;
            float r0 = 0.0, r1 = 0.0;
            int nr = 0;
            if (!(abs(A) > 1e-6 * (Q[i].x + Q[j].x))) {
                if (B != 0.0) {
                    r0 = -G / (2.0 * B);
                    nr = 1;
                }
            } else {
                float disc = B * B - A * G;
                if (disc >= 0.0) {
                    float sq = sqrt(disc), qq = -(B + (B >= 0.0 ? sq : -sq));
                    if (qq != 0.0) {
                        r0 = qq / A;
                        r1 = G / qq;
                        nr = 2;
                    } else {
                        nr = 1;
                    }
                }
            }
            if (nr > 0 && r0 > t0 && r0 < t1 && nb < VOLFX_POLY_MAX_BREAKS) br[nb++] = r0;
            if (nr > 1 && r1 > t0 && r1 < t1 && nb < VOLFX_POLY_MAX_BREAKS) br[nb++] = r1;
        }
    }
    for (int i = 1; i < nb; ++i) {
        float x = br[i];
        int j = i - 1;
        while (j >= 0 && br[j] > x) {
            br[j + 1] = br[j];
            j--;
        }
        br[j + 1] = x;
    }
    // The runs of one nearest primitive are found first and integrated after, in the same order
    // (so H is the same to the bit): llvmpipe executes the body of every `if` for all lanes, so a
    // piece evaluated inside this loop cost one sphere and one cylinder piece per interval, where
    // the loop below costs one per run (docs/benchmarks-beams.md, issue 25 cost).
    int cur = -1, runs = 0;
    float run0 = t0;
    int rprim[VOLFX_POLY_MAX_BREAKS];
    float rlo[VOLFX_POLY_MAX_BREAKS], rhi[VOLFX_POLY_MAX_BREAKS];
    for (int k = 0; k + 1 < nb; ++k) {
        if (!(br[k + 1] > br[k]))
            continue;
        float mid = 0.5 * (br[k] + br[k + 1]), best = 1e30;
        int arg = -1;
        for (int i = 0; i < m; ++i) {
            float f = volfx_prim_dist2(V, C[i], D[i], L[i], seg[i], mid);
            if (f < best) {
                best = f;
                arg = i;
            }
        }
        if (arg != cur) {
            if (cur >= 0) {
                rprim[runs] = cur;
                rlo[runs] = run0;
                rhi[runs] = br[k];
                runs++;
            }
            cur = arg;
            run0 = br[k];
        }
    }
    if (cur >= 0) {
        rprim[runs] = cur;
        rlo[runs] = run0;
        rhi[runs] = t1;
        runs++;
    }
    for (int r = 0; r < runs; ++r) {
        int i = rprim[r];
        H += b * volfx_prim_piece(V, C[i], D[i], L[i], seg[i], R, eps, rlo[r], rhi[r], soft);
    }
    return H;
}

#endif
