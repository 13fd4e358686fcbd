// Tables per band: a band's dust.tables file serves that band alone, is
// checked against that band's albedo and g, and is named in the report; the
// other scattering bands share the table cached for their (albedo, g).
#include "pipeline/table_source.h"

#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "scene/scene_file.h"
#include "scene/test_files.h"
#include "tables/table_file.h"
#include "tables/test_tables.h"

namespace nebula {
namespace {

class TableSource : public testing::TempDirTest {
 protected:
  testing::ScopedEnv cache_{"NEBULA_CACHE_DIR", path("cache")};
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
  // Each table's noise as its report states it: the file's entries carry 1% (make_test_table);
  // the generated one's, from 1000 photons a row, much more.
  EXPECT_NEAR(t.report[1].noise, 0.01, 1e-6);
  EXPECT_EQ(t.report[1].photons_per_row, 1000003u);
  EXPECT_GT(t.report[0].noise, 0.1);
  EXPECT_EQ(t.report[0].photons_per_row, 1000u);
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

// Issue 17, item 3: cache entries are keyed by the exact parameters. Names
// rounded to 6 digits made g = 0.9999995 reuse the g = 0.9999999 table.
TEST_F(TableSource, CacheEntriesAreKeyedExactly) {
  TabulateParams a, b;
  a.g = 0.9999999;
  b.g = 0.9999995;
  EXPECT_NE(table_cache_name(a), table_cache_name(b));
  b.g = a.g;
  b.albedo = std::nextafter(a.albedo, 1.0);
  EXPECT_NE(table_cache_name(a), table_cache_name(b));
  const BandTables first = resolve(scene("g = 0.9999999"));
  const BandTables second = resolve(scene("g = 0.9999995"));
  EXPECT_EQ(second.report[0].origin, TableOrigin::Generated);
  EXPECT_EQ(second.per_band[0]->g, 0.9999995);
  EXPECT_NE(first.report[0].path, second.report[0].path);
}

// Issue 17, item 3: a truncated, empty or foreign entry is generated again
// with a warning naming the cache; it blocked every later render before.
TEST_F(TableSource, BadCacheEntriesAreGeneratedAgainWithAWarning) {
  const BandTables first = resolve(scene("g = 0.5"));
  ASSERT_EQ(first.report[0].origin, TableOrigin::Generated);
  const std::string entry = first.report[0].path;
  const auto size = std::filesystem::file_size(entry);
  std::filesystem::resize_file(entry, size / 2);
  const BandTables truncated = resolve(scene("g = 0.5"));
  EXPECT_EQ(truncated.report[0].origin, TableOrigin::Generated);
  EXPECT_NE(truncated.report[0].warning.find("table cache"), std::string::npos) << truncated.report[0].warning;
  EXPECT_NE(truncated.report[0].warning.find(entry), std::string::npos) << truncated.report[0].warning;
  EXPECT_EQ(std::filesystem::file_size(entry), size);
  EXPECT_EQ(resolve(scene("g = 0.5")).report[0].origin, TableOrigin::Cache);

  std::ofstream(entry, std::ios::trunc).close();  // empty
  const BandTables empty = resolve(scene("g = 0.5"));
  EXPECT_EQ(empty.report[0].origin, TableOrigin::Generated);
  EXPECT_FALSE(empty.report[0].warning.empty());

  // A valid table of other parameters under this entry's name.
  table_file("foreign.h5", 0.6, 0.25);
  std::filesystem::copy_file(path("foreign.h5"), entry, std::filesystem::copy_options::overwrite_existing);
  const BandTables foreign = resolve(scene("g = 0.5"));
  EXPECT_EQ(foreign.report[0].origin, TableOrigin::Generated);
  EXPECT_NE(foreign.report[0].warning.find("g is 0.25, not 0.5"), std::string::npos) << foreign.report[0].warning;
  EXPECT_EQ(foreign.per_band[0]->g, 0.5);

  // An entry read and checked is kept in the process; replacing the file
  // afterwards is seen (its stamp changes), not served from memory.
  const BandTables again = resolve(scene("g = 0.5"));
  ASSERT_EQ(again.report[0].origin, TableOrigin::Cache);
  EXPECT_EQ(resolve(scene("g = 0.5")).per_band[0]->P, again.per_band[0]->P);
  std::filesystem::copy_file(path("foreign.h5"), entry, std::filesystem::copy_options::overwrite_existing);
  const BandTables replaced = resolve(scene("g = 0.5"));
  EXPECT_EQ(replaced.report[0].origin, TableOrigin::Generated);
  EXPECT_EQ(replaced.per_band[0]->g, 0.5);
}

// Issue 17, item 3: an unwritable cache folder fails before the Monte-Carlo
// work (it failed after it). Run in a child that is not root (root writes
// anywhere), with an alarm: the old code spent minutes on these photons.
TEST_F(TableSource, UnwritableCacheFailsBeforeTheWork) {
  const std::string cache = path("read_only");
  std::filesystem::create_directories(cache + "/tables");
  std::filesystem::permissions(cache + "/tables", std::filesystem::perms(0555));
  const pid_t child = ::fork();
  if (child == 0) {
    ::alarm(20);
    if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) ::_exit(3);
    setenv("NEBULA_CACHE_DIR", cache.c_str(), 1);
    TabulateParams p;
    p.photons_per_row = kMaxBasePhotons;
    try {
      cached_table(p, Backend::Cpu, false, nullptr, nullptr);
    } catch (const Error& e) {
      const std::string m = e.what();
      ::_exit(m.find("table cache") != std::string::npos && m.find("read_only") != std::string::npos ? 0 : 1);
    }
    ::_exit(2);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "the child died of signal " << WTERMSIG(status) << " (the alarm: it tabulated)";
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: the error names no cache folder; 2: no error; 3: could not drop root";
}

}  // namespace
}  // namespace nebula
