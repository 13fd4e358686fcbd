// The band physics of a scene, recomputed here independently: the filter
// curves read from data/filters by this test, the band averages by a plain
// trapezoid rule on a 0.05 nm grid, the black body by Planck's law. Only the
// extinction law itself (tested against its papers in illumination/) and the
// star's temperature are taken from the libraries.
#include "pipeline/scene_bands.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "illumination/data_dir.h"
#include "illumination/extinction.h"
#include "scene/scene_file.h"

namespace nebula {
namespace {

// A filter curve as the CSV in data/filters holds it: wavelengths in Angstrom.
struct Curve {
  std::vector<double> nm, response;
  double at(double lambda) const {
    if (lambda <= nm.front() || lambda >= nm.back()) return 0.0;
    size_t i = 1;
    while (nm[i] < lambda) ++i;
    const double f = (lambda - nm[i - 1]) / (nm[i] - nm[i - 1]);
    return (1 - f) * response[i - 1] + f * response[i];
  }
};

Curve read_curve(const std::string& band) {
  std::ifstream in(default_data_dir() + "/filters/bessell-" + band + ".csv");
  Curve c;
  std::string line;
  bool header = false;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      header = true;  // wavelength_angstrom,response
      continue;
    }
    std::istringstream row(line);
    double angstrom = 0, response = 0;
    char comma = 0;
    row >> angstrom >> comma >> response;
    c.nm.push_back(angstrom / 10.0);
    c.response.push_back(response);
  }
  return c;
}

// integral of T(lambda) f(lambda) d lambda, trapezoids of 0.05 nm.
template <class F>
double integral(const Curve& c, F f) {
  const double h = 0.05;
  const int n = static_cast<int>(std::ceil((c.nm.back() - c.nm.front()) / h));
  double sum = 0;
  for (int k = 0; k <= n; ++k) {
    const double lambda = std::min(c.nm.front() + k * h, c.nm.back());
    const double w = (k == 0 || k == n) ? 0.5 : 1.0;
    const double t = c.at(lambda);
    if (t > 0) sum += w * t * f(lambda);
  }
  return sum * h;
}

double band_average_extinction(const std::string& band, double R_V, ExtinctionLaw law) {
  const Curve c = read_curve(band);
  return integral(c, [&](double l) { return extinction_ratio_at(l, R_V, law); }) / integral(c, [](double) { return 1.0; });
}

// Planck's B_lambda up to constants, and the fraction of sigma T^4 / pi a filter passes.
double planck_fraction(const std::string& band, double T) {
  const double h = 6.62607015e-34, c = 299792458.0, k = 1.380649e-23, pi = 3.14159265358979323846;
  const double sigma = 2 * std::pow(pi, 5) * std::pow(k, 4) / (15 * c * c * std::pow(h, 3));
  auto planck = [&](double lambda_nm) {
    const double l = lambda_nm * 1e-9;
    return 2 * h * c * c / std::pow(l, 5) / std::expm1(h * c / (l * k * T));
  };
  return integral(read_curve(band), planck) * 1e-9 / (sigma * std::pow(T, 4) / pi);
}

// A small scene: `top` holds top-level keys, `tables` the rest.
Scene scene_text(const std::string& tables, const std::string& top = "") {
  return load_scene_text(top + "[density]\nprocedural = { n = 8 }\n[camera]\nposition = [1, -3, 1]\nlook_at = [1, 1, 1]\n" +
                             tables,
                         "bands.toml", ".");
}

TEST(SceneBands, ExtinctionRatiosAreBandAveragesOverTheV) {
  for (double R_V : {3.1, 5.0})
    for (ExtinctionLaw law : {ExtinctionLaw::CCM89, ExtinctionLaw::ODonnell94}) {
      Scene s = scene_text("[[stars]]\nluminosity_lsun = 1\nclass = \"G2V\"\n");
      s.dust.R_V = R_V;
      s.dust.law = law;
      const SceneBands sb = scene_bands(s);
      ASSERT_EQ(sb.bands.size(), 3u);
      const double v = band_average_extinction("V", R_V, law);
      for (size_t b = 0; b < 3; ++b) {
        const double expected = band_average_extinction(s.bands[b], R_V, law) / v;
        EXPECT_EQ(sb.bands[b].name, s.bands[b]);
        EXPECT_NEAR(sb.bands[b].extinction_ratio, expected, 2e-6 * expected) << s.bands[b] << " R_V " << R_V;
      }
      EXPECT_EQ(sb.bands[1].extinction_ratio, 1.0f);  // V is the reference, exactly
      EXPECT_GT(sb.bands[0].extinction_ratio, 1.0f);  // B is extinguished more
      EXPECT_LT(sb.bands[2].extinction_ratio, 1.0f);
    }
}

TEST(SceneBands, StarPowerIsLuminosityTimesTheFilteredBlackBody) {
  Scene s = scene_text(
      "[[stars]]\nluminosity_lsun = 2e5\nclass = \"O5V\"\n"
      "[[stars]]\nposition = [0.2, 0.3, 0.4]\nluminosity_lsun = 3\ntemperature_K = 5000\n");
  const SceneBands sb = scene_bands(s);
  ASSERT_EQ(sb.stars.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(sb.stars[k].position.x, s.stars[k].position.x);
    ASSERT_EQ(sb.stars[k].power.size(), 3u);
    for (size_t b = 0; b < 3; ++b) {
      const double expected = s.stars[k].luminosity_lsun * planck_fraction(s.bands[b], s.stars[k].temperature_K);
      EXPECT_NEAR(sb.stars[k].power[b], expected, 2e-6 * expected) << "star " << k << " band " << s.bands[b];
    }
  }
  // The hot star puts more of its power into B than into R, the cool one less.
  EXPECT_GT(sb.stars[0].power[0], sb.stars[0].power[2]);
  EXPECT_LT(sb.stars[1].power[0], sb.stars[1].power[2]);
}

TEST(SceneBands, FollowTheScenesBandsAndTheirDust) {
  Scene s = scene_text(
      "[dust]\nalbedo = { R = 0.4, V = 0.7 }\ng = { R = 0.2, V = -0.3 }\n[[stars]]\nluminosity_lsun = 1\nclass = \"B0V\"\n",
      "bands = [\"R\", \"V\"]\n");
  const SceneBands sb = scene_bands(s);
  ASSERT_EQ(sb.bands.size(), 2u);
  EXPECT_EQ(sb.bands[0].name, "R");
  EXPECT_EQ(sb.bands[1].name, "V");
  EXPECT_EQ(sb.bands[1].extinction_ratio, 1.0f);
  EXPECT_FLOAT_EQ(sb.bands[0].albedo, 0.4f);
  EXPECT_FLOAT_EQ(sb.bands[1].albedo, 0.7f);
  EXPECT_FLOAT_EQ(sb.bands[0].g, 0.2f);
  EXPECT_FLOAT_EQ(sb.bands[1].g, -0.3f);
  ASSERT_EQ(sb.filters.size(), 2u);
  EXPECT_EQ(sb.filters[0].name, "bessell-R");
  EXPECT_EQ(sb.stars[0].power.size(), 2u);
}

// Grey dust ([dust] law = "grey"): every band is extinguished as V, while the
// stars keep their filtered band powers.
TEST(SceneBands, GreyLawExtinguishesEveryBandAsV) {
  Scene s = scene_text("[dust]\nlaw = \"grey\"\nR_V = 3.1\n[[stars]]\nluminosity_lsun = 10\nclass = \"O5V\"\n");
  const SceneBands grey = scene_bands(s);
  s.dust.law = ExtinctionLaw::CCM89;
  const SceneBands ccm = scene_bands(s);
  ASSERT_EQ(grey.bands.size(), 3u);
  for (size_t b = 0; b < 3; ++b) {
    EXPECT_EQ(grey.bands[b].extinction_ratio, 1.0f) << grey.bands[b].name;
    EXPECT_EQ(grey.stars[0].power[b], ccm.stars[0].power[b]) << grey.bands[b].name;
  }
  EXPECT_GT(ccm.bands[0].extinction_ratio, 1.05f);  // B, so the law mattered
}

// The grey band: no filter, the whole bolometric luminosity, A/A_V = 1 under
// any law; beside a filtered band it changes nothing of that band.
TEST(SceneBands, GreyBandCarriesTheWholeLuminosity) {
  const Scene s = scene_text("[[stars]]\nluminosity_lsun = 250\ntemperature_K = 5800\n", "bands = [\"grey\", \"B\"]\n");
  const SceneBands sb = scene_bands(s);
  ASSERT_EQ(sb.bands.size(), 2u);
  EXPECT_EQ(sb.bands[0].name, "grey");
  EXPECT_EQ(sb.bands[0].extinction_ratio, 1.0f);
  EXPECT_TRUE(sb.filters[0].wavelength_nm.empty());
  EXPECT_EQ(sb.stars[0].power[0], 250.0f);
  EXPECT_LT(sb.stars[0].power[1], 0.5f * 250.0f);  // B passes a fraction of a 5800 K star
  Scene b_only = s;
  b_only.bands = {"B"};
  b_only.dust.albedo = {s.dust.albedo[1]};
  b_only.dust.g = {s.dust.g[1]};
  b_only.dust.table_files = {""};
  const SceneBands ref = scene_bands(b_only);
  EXPECT_EQ(sb.bands[1].extinction_ratio, ref.bands[0].extinction_ratio);
  EXPECT_EQ(sb.stars[0].power[1], ref.stars[0].power[0]);
}

TEST(SceneBands, UnknownLawNamesTheKnownOnes) {
  try {
    scene_text("[dust]\nlaw = \"fitzpatrick\"\n");
    FAIL() << "accepted an unknown law";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("dust.law"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("grey"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace nebula
