// The presets of Unity HDRP's hair textures (hdrp_preset.hpp).
#include "hdrp_preset.hpp"

#include <cmath>

#include "bake_internal.hpp"
#include "hairlut/util/angles.hpp"
#include "hairlut/util/error.hpp"

namespace hairlut::detail {
namespace {

using json = nlohmann::ordered_json;

// A table with its attributes.
Table new_table(const std::string& group, const std::string& name, const std::string& quantity, const std::string& units,
                const std::string& long_name, const std::vector<GridAxis>& axes, Precision precision, json attributes) {
  Table t = make_table(group, name, quantity, units, long_name, axes, precision);
  t.attributes = std::move(attributes);
  return t;
}

// ---- HDRP's textures, as its pre-integration kernels define them (hdrp_kernels.hpp) --------------

constexpr double kHdrpTolerance = 1e-10;  // relative accuracy of every integral of the HDRP kernels

json hdrp_source() {
  return {{"engine", "Unity HDRP (Unity-Technologies/Graphics)"},
          {"kernel", "Packages/com.unity.render-pipelines.high-definition/Runtime/Material/Hair/MultipleScattering/"
                     "HairMultipleScatteringPreIntegration.compute"},
          {"commit", "e3089c7ac636a15826cef489539d9d7e5da11820"},
          {"documentation", "docs/presets/unity-hdrp-hair.md"}};
}

// What the exact variant changes, for the tables' attributes.
const char* kExactNote = "unity-hdrp-hair-deon: HDRP's axes, mappings and integrals with exact functions: d'Eon's M_p with the exact I0 and "
                         "csch and no guard epsilon, the exact Bravais index sqrt(eta^2 - sin^2 theta_d) / cos theta_d, exact dielectric Fresnel";

void bake_hdrp_attenuation(const BakeConfig& c, const EngineTableSpec& s, hdrp::Functions fn, TableSet& set, BakeReport& report) {
  const Precision precision = c.output.hdf5_double ? Precision::float64 : Precision::float32;
  std::vector<double> d = s.axes[0].nodes(), sin_t = s.axes[1].nodes(), sm = s.axes[2].nodes();
  for (double& t : sin_t) t = std::sin(t);
  std::vector<double> front, back;
  hdrp::attenuation_table(sm, sin_t, d, front, back, kHdrpTolerance, fn);
  const char* what[2] = {"front", "back"};
  for (int k = 0; k < 2; ++k) {
    json attributes = {
        {"definition", std::string("(1/pi) int_0^pi dphi int_{") + (k ? "back" : "front") +
                           " half sphere} dw 1/2 int_{-1}^{1} dh S_HDRP(w, l(phi), h): ComputeAttenuation" + (k ? "Backward" : "Forward") +
                           " with HDRP's reference hair model (EvaluateHairReference: R, TT, TRT, residual; eta 1.55, Schlick Fresnel, "
                           "Chiang variances, trimmed logistic of radial roughness 0.3, cuticle 3 deg), integrated exactly"},
        {"source", hdrp_source()}};
    if (fn == hdrp::Functions::exact) attributes["variant"] = kExactNote;
    Table t = new_table(s.group, what[k], "attenuation", "1", std::string(what[k]) + " average attenuation as HDRP stores it", s.axes, precision,
                        attributes);
    const std::vector<double>& v = k ? back : front;
    for (std::size_t i = 0; i < v.size(); ++i) t.set(i, v[i]);
    set.tables.push_back(std::move(t));
  }
  report.entries += 2 * front.size();
}

void bake_hdrp_azimuthal(const BakeConfig& c, const EngineTableSpec& s, hdrp::Functions fn, const BakeOptions& opt, TableSet& set,
                         BakeReport& report) {
  const Precision precision = c.output.hdf5_double ? Precision::float64 : Precision::float32;
  const std::vector<double> b_nodes = s.axes[0].nodes(), cos_nodes = s.axes[1].nodes(), phis = s.axes[2].nodes();
  const std::size_t first = set.tables.size();
  for (int p = 0; p < 3; ++p)
    set.tables.push_back(new_table(s.group, "N_" + lobe_name(p), "N_p", "1/rad", "HDRP's azimuthal distribution of lobe " + lobe_name(p), s.axes,
                                   precision,
                                   {{"lobe", lobe_name(p)}, {"p", p},
                                    {"definition", "1/2 int_{-1}^{1} TrimmedLogistic(wrap(phi - Phi(p, asin h, asin(h / eta'))), s, -pi, pi) dh, "
                                                   "eta' = 1.19 / cos(theta_d) + 0.36 cos(theta_d), s = sqrt(pi/8)(0.265 b + 1.194 b^2 + 5.372 b^22) "
                                                   "(ComputeAzimuthalScattering), integrated exactly"},
                                    {"source", hdrp_source()}}));
  if (fn == hdrp::Functions::exact)
    for (std::size_t k = first; k < set.tables.size(); ++k) set.tables[k].attributes["variant"] = kExactNote;
  const std::size_t nb = b_nodes.size(), nc = cos_nodes.size(), nphi = phis.size();
  parallel_for(nc * 3, opt, s.group, 1, [&](std::size_t item) {
    const std::size_t y = item / 3;
    const int p = static_cast<int>(item % 3);
    Table& t = set.tables[first + static_cast<std::size_t>(p)];
    for (std::size_t z = 0; z < nb; ++z)
      for (std::size_t x = 0; x < nphi; ++x)
        t.set((z * nc + y) * nphi + x, hdrp::azimuthal_texel(p, phis[x], cos_nodes[y], b_nodes[z], kHdrpTolerance, fn));
  });
  report.entries += 3 * nb * nc * nphi;
}

void bake_hdrp_longitudinal(const BakeConfig& c, const EngineTableSpec& s, hdrp::Functions fn, const BakeOptions& opt, TableSet& set,
                            BakeReport& report) {
  const Precision precision = c.output.hdf5_double ? Precision::float64 : Precision::float32;
  const std::vector<double> beta = s.axes[0].nodes(), to = s.axes[1].nodes(), ti = s.axes[2].nodes();
  const std::size_t first = set.tables.size();
  for (int p = 0; p < 3; ++p)
    set.tables.push_back(new_table(s.group, "M_" + lobe_name(p), "M_p", "1/rad", "HDRP's longitudinal scattering of lobe " + lobe_name(p), s.axes,
                                   precision,
                                   {{"lobe", lobe_name(p)}, {"p", p},
                                    {"definition", "LongitudinalScattering(cos_i, cos_o', sin_i, sin_o', v_p): d'Eon's M with HDRP's 10-term I0 "
                                                   "series, v_p from LongitudinalVarianceFromBeta (v, v/4, 4v), theta_o turned by -2a, +a, +4a, "
                                                   "a = 3 deg (ComputeLongitudinalScattering)"},
                                    {"source", hdrp_source()}}));
  if (fn == hdrp::Functions::exact)
    for (std::size_t k = first; k < set.tables.size(); ++k) set.tables[k].attributes["variant"] = kExactNote;
  parallel_for(beta.size(), opt, s.group, 1, [&](std::size_t z) {
    for (std::size_t y = 0; y < to.size(); ++y)
      for (std::size_t x = 0; x < ti.size(); ++x) {
        const auto m = hdrp::longitudinal_texel(std::sin(ti[x]), std::sin(to[y]), beta[z], fn);
        for (std::size_t p = 0; p < 3; ++p) set.tables[first + p].set((z * to.size() + y) * ti.size() + x, m[p]);
      }
  });
  report.entries += 3 * beta.size() * to.size() * ti.size();
}

}  // namespace

void HdrpPreset::check(const BakeConfig& c) const {
  if (c.eta != hdrp::kEta)
    config_error("fiber.eta", name_ + " reproduces HDRP's kernels, which fix eta = 1.55 (got " + std::to_string(c.eta) + ")");
}

std::vector<EngineTableSpec> HdrpPreset::tables(bool) const {
  std::vector<EngineTableSpec> out;
  // HairMultipleScatteringPreIntegration.compute: every kernel evaluates texel id at UVW = (id + 0.5) / 64
  // and HDRP samples the 3D textures with normalised coordinates, so every axis is texel-centred.
  // Attenuation (ComputeAttenuationForward/Backward): X perceptual smoothness, Y sin(theta) of the
  // light (the shader passes |sin theta_i|), Z diffuse colour of one channel.
  EngineTableSpec s;
  s.axes = {texel_axis("diffuse_color", "1", "HDRP hair diffuse colour d (one channel); texel z at (z + 1/2)/64", Spacing::uniform, 0.0, 1.0, 64),
            texel_axis("theta_i", "rad", "inclination of the light to the normal plane (sin = dot(T, L), T root to tip; the shader "
                      "passes |sin|); texel y at sin(theta_i) = (y + 1/2)/64", Spacing::sin, 0.0, kHalfPi, 64),
            texel_axis("smoothness", "1", "HDRP hair perceptual smoothness; texel x at (x + 1/2)/64", Spacing::uniform, 0.0, 1.0, 64)};
  s.group = "unity/attenuation", s.kind = "hdrp_attenuation";
  s.absorption_axis = "diffuse_color", s.roughness_axis = "smoothness", s.theta_axis = "theta_i";
  out.push_back(s);
  // Azimuthal (ComputeAzimuthalScattering): X phi = 4pi u - 2pi, Y cos(theta_d), Z radial roughness,
  // read by GetRoughenedAzimuthalScatteringDistribution with the same coordinates.
  EngineTableSpec a;
  a.axes = {texel_axis("radial_roughness", "1", "HDRP perceptual radial (azimuthal) roughness beta_n; texel z at (z + 1/2)/64", Spacing::uniform, 0.0, 1.0, 64),
            texel_axis("cos_theta_d", "1", "cos(theta_d); texel y at (y + 1/2)/64", Spacing::uniform, 0.0, 1.0, 64),
            texel_axis("phi", "rad", "relative azimuth phi over [-2pi, 2pi]; texel x at (phi + 2pi)/4pi = (x + 1/2)/64", Spacing::uniform,
                      -kTwoPi, kTwoPi, 64)};
  a.group = "unity/azimuthal", a.kind = "hdrp_azimuthal";
  a.roughness_axis = "radial_roughness", a.theta_axis = "cos_theta_d";
  out.push_back(a);
  // Longitudinal (ComputeLongitudinalScattering): X sin theta_i = 2u - 1, Y sin theta_o = 2u - 1, Z the
  // longitudinal roughness beta_m fed to LongitudinalVarianceFromBeta (GetEnergyConservingLongitudinalScattering
  // samples X = 0.5 + 0.5 sin theta_i, Y = 0.5 + 0.5 sin theta_o, Z = perceptual roughness).
  EngineTableSpec m;
  m.axes = {texel_axis("roughness", "1", "HDRP hair perceptual roughness beta_m (Chiang's longitudinal roughness); texel z at (z + 1/2)/64",
                      Spacing::uniform, 0.0, 1.0, 64),
            texel_axis("theta_o", "rad", "inclination of the view; texel y at 0.5 + 0.5 sin(theta_o) = (y + 1/2)/64", Spacing::sin, -kHalfPi, kHalfPi, 64),
            texel_axis("theta_i", "rad", "inclination of the light; texel x at 0.5 + 0.5 sin(theta_i) = (x + 1/2)/64", Spacing::sin, -kHalfPi, kHalfPi, 64)};
  m.group = "unity/longitudinal", m.kind = "hdrp_longitudinal";
  m.roughness_axis = "roughness", m.theta_axis = "theta_i";
  out.push_back(m);
  return out;}

std::vector<EngineTexture> HdrpPreset::textures() const {
  auto table = [](std::string path, double scale, bool saturate) { return EngineChannel{std::move(path), 0.0, scale, saturate}; };
  auto constant = [](double v) { return EngineChannel{"", v, 1.0, false}; };
  std::vector<EngineTexture> out;
  EngineTexture t;
  t.preset = name_;
  // 8 x 8 cells of 64 x 64 (a 512 x 512 image, within Unity's 2048 import limit), read by Unity's
  // flipbook import (Texture Shape 3D, Columns 8, Rows 8) as slices in reading order; Unity's
  // texture origin is the bottom-left corner, so texel row 0 is the bottom row of its cell.
  t.tiles_per_row = 8;
  t.flip_y = true;
  const std::string& variant = file_prefix_;
  {
    t.name = "attenuation", t.file_suffix = variant + "attenuation", t.group = "unity/attenuation";
    t.channel_count = 2;
    t.channels[0] = table("unity/attenuation/front", 1.0, false);
    t.channels[1] = table("unity/attenuation/back", 1.0, false);
    t.channels[2] = constant(0.0);
    t.channels[3] = constant(0.0);
    t.engine_format = "R16G16_SFloat (RG half), 64 x 64 x 64; HDRP reads .xy only";
    t.description = "_HairAttenuation (HDRenderPipelineRuntimeTextures.hairAttenuationLUT): ComputeDualScattering samples (X min(smoothness, 0.6), "
                    "Y |sin theta_i|, Z diffuse colour) once per colour channel and reads .x = front and .y = back average attenuation "
                    "as ComputeAttenuationForward/Backward define them";
    out.push_back(t);
  }
  t.channel_count = 4;
  t.engine_format = "R16G16B16A16_SFloat (RGBA half), 64 x 64 x 64";
  {
    t.name = "azimuthal", t.file_suffix = variant + "azimuthal", t.group = "unity/azimuthal";
    t.channels[0] = table("unity/azimuthal/N_R", 1.0, false);
    t.channels[1] = table("unity/azimuthal/N_TT", 1.0, false);
    t.channels[2] = table("unity/azimuthal/N_TRT", 1.0, false);
    t.channels[3] = constant(1.0);
    t.description = "_HairAzimuthalScattering (hairAzimuthalScatteringLUT): GetRoughenedAzimuthalScatteringDistribution reads .xyz = N_R, "
                    "N_TT, N_TRT, the trimmed-logistic azimuthal distributions averaged over h (ComputeAzimuthalScattering)";
    out.push_back(t);
  }
  {
    t.name = "longitudinal", t.file_suffix = variant + "longitudinal", t.group = "unity/longitudinal";
    t.channels[0] = table("unity/longitudinal/M_R", 1.0, false);
    t.channels[1] = table("unity/longitudinal/M_TT", 1.0, false);
    t.channels[2] = table("unity/longitudinal/M_TRT", 1.0, false);
    t.channels[3] = constant(1.0);
    t.description = "_HairLongitudinalScattering (hairLongitudinalScatteringLUT): GetEnergyConservingLongitudinalScattering (Marschner "
                    "cinematic) reads .xyz = M_R, M_TT, M_TRT as ComputeLongitudinalScattering defines them";
    out.push_back(t);
  }
  return out;
}

void HdrpPreset::bake(const BakeConfig& c, const EngineTableSpec& s, const BakeOptions& opt, TableSet& set, BakeReport& report) const {
  if (s.kind == "hdrp_attenuation") bake_hdrp_attenuation(c, s, functions_, set, report);
  else if (s.kind == "hdrp_azimuthal") bake_hdrp_azimuthal(c, s, functions_, opt, set, report);
  else if (s.kind == "hdrp_longitudinal") bake_hdrp_longitudinal(c, s, functions_, opt, set, report);
  else throw DomainError("internal: " + name_ + " has no table kind " + s.kind);
}

// d'Eon's M_p is normalised (∫ M_p cos θi dθi = 1 at every β), so the exact variant's attenuation
// does not vary along smoothness: deflate and zip keep one smoothness row and code the others as
// repeats (measured: 2.3% of the bytes in HDF5 and 2.4% of the texture, against 43% and 11% for
// HDRP's own).
EnginePreset::GroupSize HdrpPreset::group_size(const EngineTableSpec& s) const {
  if (s.kind == "hdrp_attenuation") return {2, functions_ == hdrp::Functions::exact};
  return {3, false};
}

}  // namespace hairlut::detail
