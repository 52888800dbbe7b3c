// hairlut_sampling.glsl — sample and pdf of one hair material in a shader, as
// hairlut::sampler::MaterialScattering (material_scattering.hpp) draws them: θi from step 1's
// piecewise-quadratic rows, the lobe in proportion to M_q Z_q, φ from the lobe's N̄ row; the pdf
// per unit solid angle q(θi) / cos θi · S̄ / S̄_φ. Included by hairlut.glsl when HAIRLUT_SAMPLING
// is 1; reads the rows MaterialScattering::rows() holds, as float32 (hairlut/sampler/
// gpu_textures.hpp lays them out; guides as exact integers), from HAIRLUT_ROWS.
#ifndef HAIRLUT_ROWS
layout(set = HAIRLUT_SET, binding = HAIRLUT_BINDING + 2, std430) readonly buffer HairlutRows { float hairlut_rows[]; };
#define HAIRLUT_ROWS hairlut_rows
#endif

const int HAIRLUT_GUIDE_THETA = 64, HAIRLUT_GUIDE_PHI = 32;

// What hairlut_at holds for one wo: θo, its sine and cosine, (cos φo, sin φo), where θo falls on
// the θr axis (cell r, weight w of r + 1) and step 1's two masses.
struct HairlutPoint {
  float theta_o, sin_o, cos_o, w, a0, a1;
  vec2 phi_o;
  int r;
  bool ok;
};
// A drawn direction: wi (unit, fiber frame), S / pdf per channel, the pdf per unit solid angle
// (0: nothing drawn) and the lobe (the residual is the last).
struct HairlutSample {
  vec3 wi, weight;
  float pdf;
  int lobe;
};

// M_p of every lobe at (θi, θo).
void hairlut_mp_all(HairlutMaterial m, float theta_o, float theta_i, out float mp[8]) {
  vec2 sm = vec2(hairlut_node(m.theta_r, theta_o), hairlut_node(m.theta_i, theta_i));
  vec2 m_last = vec2(m.theta_r.z, m.theta_i.z), m_inv = vec2(m.theta_r.w, m.theta_i.w);
  int lobes = m.lobes.x + m.lobes.y;
  for (int p = 0; p < 8; ++p) mp[p] = 0.0;
  for (int k = 0; 4 * k < lobes; ++k) {
    vec4 v = hairlut_mp_bilinear(sm, m_last, m_inv, m.lobes.w + k);
    for (int c = 0; c < 4 && 4 * k + c < lobes; ++c) mp[4 * k + c] = v[c];
  }
}

// The θd axis's argument from both inclinations (1 − cos θd or |θd|, as hairlut_eval).
float hairlut_theta_d_arg(HairlutMaterial m, float so, float co, float to, float si, float ci, float ti) {
  return m.flags.x != 0 ? hairlut_one_minus_cos_theta_d(so, co, si, ci) : abs(0.5 * (to - ti));
}

// Lobe p's energy Z_p = ∫ N̄_p dφ at θd node coordinate sd and u = cos θd: an explicit lobe's
// interpolated linearly (in stored units) times its grazing factor; the residual's, uniform in φ,
// 2π times the channels' mean of its N.
float hairlut_z(HairlutMaterial m, float sd, HairlutGrazing g, int p) {
  if (p == m.lobes.x) {
    vec2 n_last = vec2(m.phi.z, m.theta_d.z), n_inv = vec2(m.phi.w, m.theta_d.w);
    vec3 n = g.res * hairlut_np_bilinear(vec2(0.0, sd), n_last, n_inv, m.lobes.z + p).rgb;
    return 2.0 * HAIRLUT_PI * (n.r + n.g + n.b) / 3.0;
  }
  int sm = (m.lobes.x + m.lobes.y + 3) / 4 * 4;
  float k = min(floor(sd), m.theta_d.z - 1.0), w = sd - k;
  int o = m.rows0.w + int(k) * sm + p;
  return hairlut_grazing(m, g, p).x * ((1.0 - w) * HAIRLUT_ROWS[o] + w * HAIRLUT_ROWS[o + sm]);
}

// S per channel from every lobe's M_p at node coordinates sn = (φ, θd) and u = cos θd, and
// S̄_φ = Σ_q M_q Z_q.
vec3 hairlut_sum(HairlutMaterial m, float mp[8], vec2 sn, HairlutGrazing g, out float s_phi) {
  vec2 n_last = vec2(m.phi.z, m.theta_d.z), n_inv = vec2(m.phi.w, m.theta_d.w);
  vec3 s = vec3(0.0);
  s_phi = 0.0;
  for (int p = 0; p < m.lobes.x + m.lobes.y; ++p) {
    vec3 v = mp[p] * hairlut_grazing(m, g, p) * hairlut_np_bilinear(sn, n_last, n_inv, m.lobes.z + p).rgb;
    s += v;
    s_phi += p == m.lobes.x ? 2.0 * HAIRLUT_PI * (v.r + v.g + v.b) / 3.0 : mp[p] * hairlut_z(m, sn.y, g, p);
  }
  return s;
}

// The cell holding target = u · total of a row's prefix masses cum[0 … n − 1], from its guide.
int hairlut_find_cell(int cum, int n, int guide, int g, float u, float target) {
  int k = int(HAIRLUT_ROWS[guide + min(int(u * float(g)), g - 1)]);
  while (k < n - 2 && HAIRLUT_ROWS[cum + k + 1] <= target) ++k;
  return k;
}

// Inverse CDF of step 1's row: density A + B s + C s² on cell k (coefficients at q + 3k).
float hairlut_invert_quadratic_row(int q, int cum, int guide, int n, float x0, float h, float u) {
  float target = u * HAIRLUT_ROWS[cum + n - 1];
  int k = hairlut_find_cell(cum, n, guide, HAIRLUT_GUIDE_THETA, u, target);
  float A = HAIRLUT_ROWS[q + 3 * k], B = HAIRLUT_ROWS[q + 3 * k + 1], C = HAIRLUT_ROWS[q + 3 * k + 2];
  float mass = max(0.0, target - HAIRLUT_ROWS[cum + k]) / h, total = A + 0.5 * B + C / 3.0;
  if (!(total > 0.0)) return x0 + (float(k) + 0.5) * h;
  float root = sqrt(max(0.0, A * A + 2.0 * B * mass));
  float lo = 0.0, hi = 1.0, t = A + root > 0.0 ? min(1.0, 2.0 * mass / (A + root)) : min(1.0, mass / total);
  for (int it = 0; it < 12; ++it) {
    float f = t * (A + t * (0.5 * B + t * C / 3.0)) - mass, d = A + t * (B + t * C);
    if (f > 0.0) hi = t;
    else lo = t;
    float next = d > 0.0 ? t - f / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    bool done = abs(next - t) < 1e-7;  // of the cell: float's resolution there
    t = next;
    if (done) break;
  }
  return x0 + (float(k) + t) * h;
}

// Inverse CDF of a piecewise-linear density on n nodes of step h from 0 (values v, masses cum).
float hairlut_invert_row(int v, int cum, int guide, int n, float h, float u) {
  float target = u * HAIRLUT_ROWS[cum + n - 1];
  int k = hairlut_find_cell(cum, n, guide, HAIRLUT_GUIDE_PHI, u, target);
  float mass = max(0.0, target - HAIRLUT_ROWS[cum + k]) / h, a = HAIRLUT_ROWS[v + k], b = HAIRLUT_ROWS[v + k + 1];
  float root = sqrt(max(0.0, a * a + 2.0 * (b - a) * mass));
  float t = a + root > 0.0 ? 2.0 * mass / (a + root) : 0.5;
  return (float(k) + clamp(t, 0.0, 1.0)) * h;
}

// q(θi) / cos θi · S̄ / S̄_φ at the point.
float hairlut_density(HairlutMaterial m, HairlutPoint pt, float theta_i, float cos_i, vec3 s, float s_phi) {
  float sbar = (s.r + s.g + s.b) / 3.0;
  if (!(cos_i > 0.0) || !(s_phi > 0.0) || !(sbar > 0.0)) return 0.0;
  int nc = m.rows1.w - 1;
  float sq = clamp((theta_i - m.rows2.y) / m.rows2.x, 0.0, float(nc));
  int k = min(int(sq), nc - 1);
  float x = sq - float(k);
  int g0 = m.rows0.x + (pt.r * nc + k) * 3, g1 = g0 + 3 * nc;
  float q = (1.0 - pt.w) * (HAIRLUT_ROWS[g0] + x * (HAIRLUT_ROWS[g0 + 1] + x * HAIRLUT_ROWS[g0 + 2])) +
            pt.w * (HAIRLUT_ROWS[g1] + x * (HAIRLUT_ROWS[g1 + 1] + x * HAIRLUT_ROWS[g1 + 2]));
  return q / ((pt.a0 + pt.a1) * cos_i) * (sbar / s_phi);  // sbar / s_phi first: both may be tiny, their product with q underflow
}

// The shading point seen from wo (unit, fiber frame), as HairScattering::at.
HairlutPoint hairlut_at(HairlutMaterial m, vec3 wo) {
  HairlutPoint pt;
  HairlutIncl o = hairlut_inclination(wo);
  pt.sin_o = o.s, pt.cos_o = o.c, pt.theta_o = o.theta;
  pt.phi_o = o.c > 0.0 ? wo.yz / o.c : vec2(1.0, 0.0);
  float sr = hairlut_node(m.theta_r, pt.theta_o);
  float cell = min(floor(sr), m.theta_r.z - 1.0);
  pt.r = int(cell), pt.w = sr - cell;
  int nq = m.rows1.w;
  pt.a0 = (1.0 - pt.w) * HAIRLUT_ROWS[m.rows0.y + pt.r * nq + nq - 1];
  pt.a1 = pt.w * HAIRLUT_ROWS[m.rows0.y + (pt.r + 1) * nq + nq - 1];
  float total = pt.a0 + pt.a1;
  pt.ok = total > 0.0 && !isinf(total);
  return pt;
}

// The pdf per unit solid angle with which hairlut_sample draws wi at the point.
float hairlut_pdf(HairlutMaterial m, HairlutPoint pt, vec3 wi) {
  if (!pt.ok) return 0.0;
  float cross_ = pt.phi_o.x * wi.z - pt.phi_o.y * wi.y, dot_ = pt.phi_o.x * wi.y + pt.phi_o.y * wi.z;
  float phi = hairlut_atan2_upper(abs(cross_), dot_);
  HairlutIncl i = hairlut_inclination(wi);
  float si = i.s, ci = i.c, ti = i.theta;
  float mp[8];
  hairlut_mp_all(m, pt.theta_o, ti, mp);
  float x = hairlut_theta_d_arg(m, pt.sin_o, pt.cos_o, pt.theta_o, si, ci, ti), s_phi;
  HairlutGrazing g = hairlut_grazing_at(m, hairlut_cos_theta_d(pt.sin_o, pt.cos_o, si, ci));
  vec3 s = hairlut_sum(m, mp, vec2(hairlut_node(m.phi, phi), hairlut_node(m.theta_d, x)), g, s_phi);
  return hairlut_density(m, pt, ti, ci, s, s_phi);
}

// Draws wi from u ∈ [0, 1)³ as HairScattering's sample: u.x the θr row and then the lobe, u.y θi,
// u.z φ.
HairlutSample hairlut_sample(HairlutMaterial m, HairlutPoint pt, vec3 u) {
  HairlutSample d;
  d.wi = vec3(0.0), d.weight = vec3(0.0), d.pdf = 0.0, d.lobe = -1;
  if (!pt.ok) return d;
  u = clamp(u, 9.094947e-13, 0.99999994);  // off 0 and 1, as the C++ runtime keeps them
  // 1. The θr row by u.x, then θi from that row by u.y.
  float u0 = u.x * (pt.a0 + pt.a1);
  int r = pt.r;
  if (u0 < pt.a0 || !(pt.a1 > 0.0)) {
    u0 = pt.a0 > 0.0 ? u0 / pt.a0 : 0.5;
  } else {
    u0 = (u0 - pt.a0) / pt.a1;
    ++r;
  }
  u0 = clamp(u0, 0.0, 1.0);
  int nq = m.rows1.w, nc = nq - 1;
  float ti = hairlut_invert_quadratic_row(m.rows0.x + r * nc * 3, m.rows0.y + r * nq, m.rows0.z + r * HAIRLUT_GUIDE_THETA, nq, m.rows2.y,
                                          m.rows2.x, u.y);
  float si = sin(ti), ci = cos(ti);
  // 2. The lobe at θi in proportion to M_q Z_q.
  float mp[8], share[8];
  hairlut_mp_all(m, pt.theta_o, ti, mp);
  float sd = hairlut_node(m.theta_d, hairlut_theta_d_arg(m, pt.sin_o, pt.cos_o, pt.theta_o, si, ci, ti));
  HairlutGrazing gd = hairlut_grazing_at(m, hairlut_cos_theta_d(pt.sin_o, pt.cos_o, si, ci));
  int lobes = m.lobes.x + m.lobes.y;
  float norm = 0.0;
  for (int p = 0; p < lobes; ++p) {
    share[p] = mp[p] * hairlut_z(m, sd, gd, p);
    norm += share[p];
  }
  if (!(norm > 0.0) || isinf(norm)) return d;
  u0 *= norm;
  int q = -1;
  for (int p = 0; p < lobes; ++p) {
    if (!(share[p] > 0.0)) continue;
    q = p;
    if (u0 < share[p]) break;
    u0 -= share[p];
  }
  if (q < 0) return d;
  u0 = clamp(u0 / share[q], 0.0, 1.0);
  // 3. φ: the residual uniformly; a lobe from its θd row k or k + 1 by u0, |φ| by u.z folded.
  float phi;
  if (q == m.lobes.x) {
    phi = (2.0 * u.z - 1.0) * HAIRLUT_PI;
  } else {
    int sm = (lobes + 3) / 4 * 4, nt = int(m.theta_d.z) + 1, nf = int(m.phi.z) + 1;
    float kd = min(floor(sd), m.theta_d.z - 1.0), wd = sd - kd;
    float b0 = (1.0 - wd) * HAIRLUT_ROWS[m.rows0.w + int(kd) * sm + q], b1 = wd * HAIRLUT_ROWS[m.rows0.w + (int(kd) + 1) * sm + q];
    int row = q * nt + int(kd) + (u0 * (b0 + b1) < b0 || !(b1 > 0.0) ? 0 : 1);
    phi = hairlut_invert_row(m.rows1.x + row * nf, m.rows1.y + row * nf, m.rows1.z + row * HAIRLUT_GUIDE_PHI, nf, HAIRLUT_PI / m.phi.z,
                             abs(2.0 * u.z - 1.0));
    if (u.z < 0.5) phi = -phi;
  }
  float s_phi;
  vec3 s = hairlut_sum(m, mp, vec2(hairlut_node(m.phi, abs(phi)), sd), gd, s_phi);
  d.pdf = hairlut_density(m, pt, ti, ci, s, s_phi);
  if (!(d.pdf > 0.0) || isinf(d.pdf)) {
    d.pdf = 0.0;
    return d;
  }
  // φi = φo − φ by the angle-difference identities.
  float cf = cos(phi), sf = sin(phi);
  d.wi = vec3(si, ci * (pt.phi_o.x * cf + pt.phi_o.y * sf), ci * (pt.phi_o.y * cf - pt.phi_o.x * sf));
  d.weight = s / d.pdf;
  d.lobe = q;
  return d;
}
