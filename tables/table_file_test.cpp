#include "tables/table_file.h"

#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/test_support.h"
#include "tables/test_tables.h"

namespace nebula {
namespace {

namespace fs = std::filesystem;
using testing::expect_error;
using testing::make_test_table;

void expect_same_table(const ScatteringTable& a, const ScatteringTable& b) {
  EXPECT_EQ(a.albedo, b.albedo);
  EXPECT_EQ(a.g, b.g);
  EXPECT_EQ(a.phase, b.phase);
  EXPECT_EQ(a.geometry, b.geometry);
  EXPECT_EQ(a.illumination, b.illumination);
  EXPECT_EQ(a.mu_binning, b.mu_binning);
  EXPECT_EQ(a.photons_per_row, b.photons_per_row);
  EXPECT_EQ(a.thin_boost, b.thin_boost);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.rng, b.rng);
  EXPECT_EQ(a.schema_version, b.schema_version);
  EXPECT_EQ(a.generator, b.generator);
  EXPECT_EQ(a.forced_first_scattering, b.forced_first_scattering);
  EXPECT_EQ(a.roulette_threshold, b.roulette_threshold);
  EXPECT_EQ(a.roulette_survival, b.roulette_survival);
  EXPECT_EQ(a.max_orders, b.max_orders);
  EXPECT_EQ(a.capped_photons, b.capped_photons);
  EXPECT_EQ(a.scattering_events, b.scattering_events);
  // Vector equality is element-wise ==: exact, bit for bit for finite values.
  EXPECT_EQ(a.tau, b.tau);
  EXPECT_EQ(a.mu_edges, b.mu_edges);
  EXPECT_EQ(a.mu, b.mu);
  EXPECT_EQ(a.P, b.P);
  EXPECT_EQ(a.P_stderr, b.P_stderr);
  EXPECT_EQ(a.total, b.total);
  EXPECT_EQ(a.total_stderr, b.total_stderr);
  EXPECT_EQ(a.unscattered, b.unscattered);
}

// Each test works in its own fresh directory.
class TableFile : public ::testing::Test, protected testing::ScratchDir {
 protected:
  TableFile() : ScratchDir("nebula_tables") {}
};

TEST_F(TableFile, RoundTripPreservesEveryField) {
  for (AngularBinning binning : {AngularBinning::UniformMu, AngularBinning::UniformTheta}) {
    const ScatteringTable written = make_test_table(7.5, 31, binning, 72, -0.3);
    const std::string file = path(std::string(to_string(binning)) + ".h5");
    write_table(written, file, false);
    const ScatteringTable read = read_table(file);
    expect_same_table(written, read);
  }
  // Only the two targets remain: no temporary file is left beside them.
  EXPECT_EQ(files().size(), 2u);
}

TEST_F(TableFile, PencilAndUnforcedRoundTrip) {
  ScatteringTable written = make_test_table();
  written.illumination = "pencil";
  written.forced_first_scattering = false;
  written.max_orders = -1;
  written.seed = 0;
  write_table(written, path("t.h5"), false);
  expect_same_table(written, read_table(path("t.h5")));
}

TEST_F(TableFile, OverwriteOnlyWhenAsked) {
  const std::string file = path("t.h5");
  const ScatteringTable first = make_test_table(5.0, 11);
  write_table(first, file, false);

  ScatteringTable second = make_test_table(5.0, 11);
  second.seed = 42;
  expect_error([&] { write_table(second, file, false); }, {"cannot write", file, "exists"});
  EXPECT_EQ(read_table(file).seed, first.seed);  // untouched

  write_table(second, file, true);
  EXPECT_EQ(read_table(file).seed, 42u);
  EXPECT_EQ(files().size(), 1u);
}

TEST_F(TableFile, InconsistentTableIsNotWritten) {
  ScatteringTable t = make_test_table();
  t.albedo = 1.5;
  const std::string file = path("t.h5");
  expect_error([&] { write_table(t, file, false); }, {file, "albedo"});
  EXPECT_TRUE(files().empty());
}

TEST_F(TableFile, MissingDirectoryIsRefusedCleanly) {
  const std::string file = path("no/such/dir/t.h5");
  expect_error([&] { write_table(make_test_table(), file, false); },
               {"cannot write " + file + ": No such file or directory"});
  EXPECT_TRUE(files().empty());
}

TEST_F(TableFile, DirectoryThatIsAFileIsRefusedCleanly) {
  std::ofstream(path("plain")) << "not a directory\n";
  const std::string file = path("plain/t.h5");
  expect_error([&] { write_table(make_test_table(), file, false); },
               {"cannot write " + file + ": Not a directory"});
  EXPECT_EQ(files().size(), 1u);
}

TEST_F(TableFile, TargetThatIsADirectoryIsRefused) {
  fs::create_directory(path("t.h5"));
  expect_error([&] { write_table(make_test_table(), path("t.h5"), true); },
               {"cannot write", path("t.h5"), "directory"});
}

TEST_F(TableFile, ReadOnlyDirectoryIsRefusedCleanly) {
  if (::geteuid() == 0) GTEST_SKIP() << "running as root, which may write into read-only directories";
  fs::permissions(dir_, fs::perms::owner_read | fs::perms::owner_exec);
  const std::string file = path("t.h5");
  expect_error([&] { write_table(make_test_table(), file, false); },
               {"cannot write " + file + ": Permission denied"});
  fs::permissions(dir_, fs::perms::owner_all);
  EXPECT_TRUE(files().empty());
}

// Writes under a 16 KiB file-size limit and exits 0 when the write failed
// with a message naming the path and left no file in `dir`.
[[noreturn]] void write_under_size_limit(const ScatteringTable& t, const std::string& file,
                                         const fs::path& dir) {
  ::signal(SIGXFSZ, SIG_IGN);  // make write() fail with EFBIG instead of killing us
  rlimit limit{};
  limit.rlim_cur = limit.rlim_max = 16384;
  ::setrlimit(RLIMIT_FSIZE, &limit);
  int code = 0;
  try {
    write_table(t, file, false);
    std::cerr << "write succeeded despite the limit\n";
    code = 1;
  } catch (const Error& e) {
    const std::string message = e.what();
    std::cerr << message << "\n";
    if (message.find("cannot write " + file) == std::string::npos) code = 2;
  }
  for (const auto& entry : fs::directory_iterator(dir)) {
    std::cerr << "left behind: " << entry.path() << "\n";
    code = 3;
  }
  std::exit(code);
}

// A write that fails half-way (here: the file-size limit, as a full disk
// would) reports the path and leaves neither the target nor the temporary.
TEST_F(TableFile, FailureMidWriteLeavesNothing) {
  const ScatteringTable t = make_test_table(10.0, 200, AngularBinning::UniformTheta, 180);
  EXPECT_EXIT(write_under_size_limit(t, path("big.h5"), dir_), ::testing::ExitedWithCode(0),
              "cannot write");
  EXPECT_TRUE(files().empty());
}

// ------------------------------------------------------- refused files

// Opens an existing file for editing with the HDF5 C API.
class Editor {
 public:
  explicit Editor(const std::string& file) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    file_ = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    if (file_ < 0) throw std::runtime_error("test could not open " + file);
  }
  ~Editor() { H5Fclose(file_); }

  void remove(const char* name) { H5Ldelete(file_, name, H5P_DEFAULT); }
  void remove_attribute(const char* name) { H5Adelete(file_, name); }

  void replace_dataset(const char* name, hid_t memory_type, const void* data,
                       std::vector<hsize_t> dims) {
    remove(name);
    const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
    const hid_t set = H5Dcreate2(file_, name, memory_type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(set, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    H5Dclose(set);
    H5Sclose(space);
  }
  // Overwrites the data of an existing dataset in place.
  void write(const char* name, hid_t memory_type, const void* data) {
    const hid_t set = H5Dopen2(file_, name, H5P_DEFAULT);
    H5Dwrite(set, memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data);
    H5Dclose(set);
  }
  void set_attribute(const char* name, hid_t type, const void* value) {
    if (H5Aexists(file_, name) > 0) H5Adelete(file_, name);
    const hid_t space = H5Screate(H5S_SCALAR);
    const hid_t attr = H5Acreate2(file_, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(attr, type, value);
    H5Aclose(attr);
    H5Sclose(space);
  }
  void set_fixed_string(const char* name, const std::string& value, H5T_str_t padding) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, value.size() + 4);
    H5Tset_strpad(type, padding);
    std::string padded = value;
    padded.resize(value.size() + 4, padding == H5T_STR_SPACEPAD ? ' ' : '\0');
    set_attribute(name, type, padded.data());
    H5Tclose(type);
  }
  void set_variable_string(const char* name, const std::string& value) {
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    const char* text = value.c_str();
    set_attribute(name, type, &text);
    H5Tclose(type);
  }

 private:
  hid_t file_;
};

class RefusedFile : public TableFile {
 protected:
  // A valid file, edited by `edit`, then read: the error must name the file and field.
  template <class Edit>
  void expect_refused(Edit edit, const std::vector<std::string>& pieces) {
    const std::string file = path("t.h5");
    write_table(table_, file, true);
    {
      Editor editor(file);
      edit(editor);
    }
    std::vector<std::string> all{file + ": "};
    all.insert(all.end(), pieces.begin(), pieces.end());
    expect_error([&] { read_table(file); }, all);
  }

  const ScatteringTable table_ = make_test_table(5.0, 11, AngularBinning::UniformMu, 36);
};

TEST_F(RefusedFile, MissingP) {
  expect_refused([](Editor& e) { e.remove("/P"); }, {"/P: expected", "no such dataset"});
}

TEST_F(RefusedFile, MissingUnscattered) {
  expect_refused([](Editor& e) { e.remove("/unscattered"); }, {"/unscattered", "no such dataset"});
}

TEST_F(RefusedFile, PWithTheWrongShape) {
  const std::vector<float> data(11 * 35, 0.0f);
  expect_refused(
      [&](Editor& e) { e.replace_dataset("/P", H5T_NATIVE_FLOAT, data.data(), {11, 35}); },
      {"/P: expected 2-D float dataset [11][36] matching /tau and /mu", "found rank 2 [11][35]"});
}

TEST_F(RefusedFile, PWithTheWrongRank) {
  const std::vector<float> data(11 * 36, 0.0f);
  expect_refused(
      [&](Editor& e) { e.replace_dataset("/P", H5T_NATIVE_FLOAT, data.data(), {11 * 36}); },
      {"/P: expected 2-D float dataset [11][36]", "found rank 1 [396]"});
}

TEST_F(RefusedFile, PWithAnIntegerType) {
  const std::vector<int> data(11 * 36, 0);
  expect_refused(
      [&](Editor& e) { e.replace_dataset("/P", H5T_NATIVE_INT, data.data(), {11, 36}); },
      {"/P: expected", "class integer"});
}

TEST_F(RefusedFile, MuEdgesOfTheWrongLength) {
  const std::vector<double> edges(36, 0.0);
  expect_refused(
      [&](Editor& e) { e.replace_dataset("/mu_edges", H5T_NATIVE_DOUBLE, edges.data(), {36}); },
      {"/mu_edges: expected 1-D float dataset [37]", "found rank 1 [36]"});
}

TEST_F(RefusedFile, NaNInP) {
  std::vector<float> data = table_.P;
  data[100] = NAN;
  expect_refused([&](Editor& e) { e.write("/P", H5T_NATIVE_FLOAT, data.data()); },
                 {"/P: expected finite values >= 0", "nan at [2][28]"});
}

TEST_F(RefusedFile, TauNotUniform) {
  std::vector<double> tau = table_.tau;
  tau[5] += 0.01;
  expect_refused([&](Editor& e) { e.write("/tau", H5T_NATIVE_DOUBLE, tau.data()); },
                 {"/tau: expected uniform"});
}

TEST_F(RefusedFile, TotalNotMatchingP) {
  std::vector<double> total = table_.total;
  total[3] *= 1.01;
  expect_refused([&](Editor& e) { e.write("/total", H5T_NATIVE_DOUBLE, total.data()); },
                 {"/total: expected", "row 3"});
}

TEST_F(RefusedFile, WrongSchemaVersion) {
  const int version = 2;
  expect_refused([&](Editor& e) { e.set_attribute("schema_version", H5T_NATIVE_INT, &version); },
                 {"schema_version: expected 1", "found 2"});
}

TEST_F(RefusedFile, AlbedoAboveOne) {
  const double albedo = 1.5;
  expect_refused([&](Editor& e) { e.set_attribute("albedo", H5T_NATIVE_DOUBLE, &albedo); },
                 {"albedo: expected a value in [0, 1]", "found 1.5"});
}

TEST_F(RefusedFile, AlbedoAsAString) {
  expect_refused([](Editor& e) { e.set_variable_string("albedo", "0.6"); },
                 {"albedo: expected a scalar float64 attribute", "class string"});
}

TEST_F(RefusedFile, SeedAsAFloat) {
  const double seed = 3.0;
  expect_refused([&](Editor& e) { e.set_attribute("seed", H5T_NATIVE_DOUBLE, &seed); },
                 {"seed: expected", "class float"});
}

TEST_F(RefusedFile, NegativeSeed) {
  const long long seed = -5;
  expect_refused([&](Editor& e) { e.set_attribute("seed", H5T_NATIVE_LLONG, &seed); },
                 {"seed: expected", "found -5"});
}

TEST_F(RefusedFile, MissingAttribute) {
  expect_refused([](Editor& e) { e.remove_attribute("photons_per_row"); },
                 {"photons_per_row: expected", "no such attribute"});
}

// Tables written before thin rows got more photons have no thin_boost: they
// read as 1 (the same photons in every row); a 0 is refused.
TEST_F(RefusedFile, MissingThinBoostReadsAsOneAndZeroIsRefused) {
  const std::string file = path("old.h5");
  write_table(table_, file, true);
  {
    Editor editor(file);
    editor.remove_attribute("thin_boost");
  }
  EXPECT_EQ(read_table(file).thin_boost, 1u);
  const unsigned long long zero = 0;
  expect_refused([&](Editor& e) { e.set_attribute("thin_boost", H5T_NATIVE_ULLONG, &zero); },
                 {"thin_boost: expected", ">= 1"});
}

TEST_F(RefusedFile, UnknownBinning) {
  expect_refused([](Editor& e) { e.set_variable_string("mu_binning", "uniform-cos"); },
                 {"mu_binning: expected", "\"uniform-cos\""});
}

TEST_F(RefusedFile, BinningThatDoesNotMatchTheEdges) {
  expect_refused([](Editor& e) { e.set_variable_string("mu_binning", "uniform-theta"); },
                 {"/mu_edges: expected uniform-theta edge"});
}

TEST_F(RefusedFile, ForeignPhaseFunction) {
  expect_refused([](Editor& e) { e.set_fixed_string("phase", "rayleigh", H5T_STR_NULLTERM); },
                 {"phase: expected \"henyey-greenstein\"", "found \"rayleigh\""});
}

TEST_F(RefusedFile, ForcedFlagNotBoolean) {
  const int forced = 3;
  expect_refused(
      [&](Editor& e) { e.set_attribute("forced_first_scattering", H5T_NATIVE_INT, &forced); },
      {"forced_first_scattering: expected 0 or 1"});
}

// We write fixed-length NUL-terminated strings; other tools (h5py, MATLAB)
// may write variable-length or padded ones, which must read the same.
TEST_F(TableFile, StringsOfEveryKindAreRead) {
  const std::string file = path("t.h5");
  const ScatteringTable t = make_test_table();
  write_table(t, file, false);
  {
    Editor editor(file);
    editor.set_variable_string("phase", "henyey-greenstein");
    editor.set_variable_string("rng", "philox4x32-10");
    editor.set_fixed_string("generator", t.generator, H5T_STR_SPACEPAD);
    editor.set_fixed_string("mu_binning", "uniform-mu", H5T_STR_NULLPAD);
  }
  expect_same_table(t, read_table(file));
}

TEST_F(TableFile, MissingFileIsRefused) {
  const std::string file = path("absent.h5");
  expect_error([&] { read_table(file); }, {file + ": ", "no such file"});
}

TEST_F(TableFile, TextFileIsRefused) {
  const std::string file = path("notes.h5");
  std::ofstream(file) << "tau,mu,P\n0,1,0\n";
  expect_error([&] { read_table(file); }, {file + ": ", "not an HDF5 file"});
}

TEST_F(TableFile, EmptyHdf5FileIsRefused) {
  const std::string file = path("empty.h5");
  H5Fclose(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT));
  expect_error([&] { read_table(file); }, {file + ": ", "schema_version", "no such attribute"});
}

TEST_F(TableFile, DirectoryIsRefused) {
  expect_error([&] { read_table(dir_.string()); }, {dir_.string(), "directory"});
}

// Cut-off copies of a valid file must give an Error at every length, never a crash.
TEST_F(TableFile, TruncatedFilesAreRefused) {
  const std::string good = path("good.h5");
  write_table(make_test_table(), good, false);
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 2000u);
  for (size_t length : {size_t(0), size_t(8), size_t(100), size_t(512), size_t(2000),
                        bytes.size() / 2, bytes.size() - 1}) {
    const std::string cut = path("cut.h5");
    std::ofstream(cut, std::ios::binary | std::ios::trunc).write(bytes.data(), length);
    expect_error([&] { read_table(cut); }, {cut + ": "});
  }
}

// Bit flips anywhere in a file: each read either refuses with an Error or
// returns a table (which then passed check_consistency); it never crashes.
// Metadata damage is caught by the 1.8 format's checksums.
TEST_F(TableFile, DamagedFilesNeverCrash) {
  const std::string good = path("good.h5");
  write_table(make_test_table(), good, false);
  std::ifstream in(good, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::mt19937 rng(7);
  int refused = 0;
  const int trials = 400;
  for (int trial = 0; trial < trials; ++trial) {
    std::string damaged = bytes;
    const int flips = 1 + static_cast<int>(rng() % 3);
    for (int f = 0; f < flips; ++f) damaged[rng() % damaged.size()] ^= static_cast<char>(1u << (rng() % 8));
    const std::string bad = path("bad.h5");
    std::ofstream(bad, std::ios::binary | std::ios::trunc) << damaged;
    try {
      read_table(bad);
    } catch (const Error& e) {
      ++refused;
      EXPECT_EQ(std::string(e.what()).rfind(bad + ": ", 0), 0u) << e.what();
    }
  }
  EXPECT_GT(refused, trials / 2);
}

}  // namespace
}  // namespace nebula
