// Tables per band: a band's dust.tables file serves that band alone, is
// checked against that band's albedo and g, and is named in the report; the
// other scattering bands share the table cached for their (albedo, g).
#include "pipeline/table_source.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include "scene/scene_file.h"
#include "scene/test_files.h"
#include "tables/table_file.h"
#include "tables/test_tables.h"

namespace nebula {
namespace {

class TableSource : public testing::TempDirTest {
 protected:
  void SetUp() override {
    const char* old = std::getenv("NEBULA_CACHE_DIR");
    saved_ = old ? old : "";
    had_ = old != nullptr;
    setenv("NEBULA_CACHE_DIR", path("cache").c_str(), 1);
  }
  void TearDown() override {
    if (had_)
      setenv("NEBULA_CACHE_DIR", saved_.c_str(), 1);
    else
      unsetenv("NEBULA_CACHE_DIR");
  }
  // A table file marked as ours: 1000003 photons per row (generated ones here have 1000).
  void table_file(const std::string& name, double albedo, double g) {
    ScatteringTable t = testing::make_test_table(5.0, 11, AngularBinning::UniformTheta, 36, g);
    t.albedo = albedo;
    write_table(t, path(name), true);
  }
  Scene scene(const std::string& dust) {
    return load_scene(write_text("scene.toml", "[density]\nprocedural = { n = 8 }\n[dust]\n" + dust +
                                                   "\n[[stars]]\nluminosity_lsun = 1\nclass = \"G2V\"\n"
                                                   "[camera]\nposition = [1, -3, 1]\nlook_at = [1, 1, 1]\n"));
  }
  BandTables resolve(const Scene& s) { return resolve_tables(s, {Backend::Cpu, 1000, false}); }

 private:
  std::string saved_;
  bool had_ = false;
};

TEST_F(TableSource, ABandsFileServesThatBandOnly) {
  table_file("t07.h5", 0.7, 0.5);
  const BandTables t = resolve(scene("albedo = { B = 0.6, V = 0.7, R = 0.6 }\ng = { B = 0.6, V = 0.5, R = 0.6 }\n"
                                     "tables = { V = \"t07.h5\" }"));
  ASSERT_EQ(t.per_band.size(), 3u);
  EXPECT_EQ(t.per_band[1]->photons_per_row, 1000003u);  // V: the file
  EXPECT_EQ(t.per_band[0]->photons_per_row, 1000u);     // B and R: generated, one table
  EXPECT_EQ(t.per_band[0], t.per_band[2]);
  ASSERT_EQ(t.report.size(), 2u);
  EXPECT_EQ(t.report[0].bands, (std::vector<std::string>{"B", "R"}));
  EXPECT_EQ(t.report[0].origin, TableOrigin::Generated);
  EXPECT_EQ(t.report[1].bands, (std::vector<std::string>{"V"}));
  EXPECT_EQ(t.report[1].origin, TableOrigin::File);
  EXPECT_EQ(t.report[1].path, path("t07.h5"));
  // The second time the generated table comes from the cache.
  const BandTables again = resolve(scene("albedo = { B = 0.6, V = 0.7, R = 0.6 }\ng = { B = 0.6, V = 0.5, R = 0.6 }\n"
                                         "tables = { V = \"t07.h5\" }"));
  EXPECT_EQ(again.report[0].origin, TableOrigin::Cache);
}

TEST_F(TableSource, AFileForAnotherAlbedoOrGIsRefusedNamingTheKey) {
  table_file("t07.h5", 0.7, 0.5);
  testing::expect_error([&] { resolve(scene("tables = { V = \"t07.h5\" }")); },
                        {"dust.tables.V", "t07.h5", "albedo 0.7, g 0.5", "band V has albedo 0.6, g 0.6"});
}

TEST_F(TableSource, ABandWithTheSameDustButNoFileGetsItsOwnTable) {
  table_file("other.h5", 0.6, 0.6);
  const BandTables t = resolve(scene("tables = { B = \"other.h5\" }"));
  EXPECT_EQ(t.per_band[0]->photons_per_row, 1000003u);
  EXPECT_EQ(t.per_band[1]->photons_per_row, 1000u);
  EXPECT_EQ(t.per_band[1], t.per_band[2]);
  ASSERT_EQ(t.report.size(), 2u);
  EXPECT_EQ(t.report[0].bands, (std::vector<std::string>{"B"}));
  EXPECT_EQ(t.report[1].bands, (std::vector<std::string>{"V", "R"}));
}

TEST_F(TableSource, OneFileNamedTwiceIsReadOnceAndABandWithoutAlbedoNeedsNone) {
  table_file("shared.h5", 0.6, 0.6);
  const BandTables t = resolve(scene("albedo = { B = 0.6, V = 0.6, R = 0.0 }\n"
                                     "tables = { B = \"shared.h5\", V = \"shared.h5\" }"));
  EXPECT_EQ(t.per_band[0], t.per_band[1]);
  EXPECT_EQ(t.per_band[2], nullptr);
  ASSERT_EQ(t.report.size(), 1u);
  EXPECT_EQ(t.report[0].bands, (std::vector<std::string>{"B", "V"}));
}

}  // namespace
}  // namespace nebula
