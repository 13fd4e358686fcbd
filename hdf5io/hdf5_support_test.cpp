#include "hdf5io/hdf5_support.h"

#include <gtest/gtest.h>

#include <signal.h>

#include <filesystem>
#include <string>
#include <thread>

#include "core/error.h"

namespace nebula::hdf5io {
namespace {

TEST(Hdf5Support, HandleClosesAtScopeExit) {
  hid_t id = H5I_INVALID_HID;
  {
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    ASSERT_TRUE(space.valid());
    id = space.get();
    EXPECT_GT(H5Iis_valid(id), 0);
  }
  EXPECT_EQ(H5Iis_valid(id), 0);
}

TEST(Hdf5Support, MovedFromHandleDoesNotCloseTwice) {
  Handle a(H5Screate(H5S_SCALAR), H5Sclose);
  const hid_t id = a.get();
  Handle b(std::move(a));
  EXPECT_FALSE(a.valid());
  EXPECT_TRUE(a.close());  // nothing left to close
  EXPECT_GT(H5Iis_valid(id), 0);
  EXPECT_TRUE(b.close());
  EXPECT_EQ(H5Iis_valid(id), 0);
}

// tables/, imageio/ and scene/ must exclude each other: one lock, not one each.
TEST(Hdf5Support, OneMutexForTheProgram) {
  std::mutex* first = &hdf5_mutex();
  std::mutex* second = &hdf5_mutex();
  EXPECT_EQ(first, second);
  const std::lock_guard<std::mutex> lock(hdf5_mutex());
  bool taken = true;
  std::thread([&] {  // try_lock from the owning thread would be undefined
    taken = second->try_lock();
    if (taken) second->unlock();
  }).join();
  EXPECT_FALSE(taken);
}

TEST(Hdf5Support, ReasonIsTheSystemsText) {
  const std::lock_guard<std::mutex> lock(hdf5_mutex());
  silence_hdf5_errors();
  const std::string path =
      (std::filesystem::temp_directory_path() / "nebula_hdf5io_no_such_folder" / "a.h5").string();
  Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
  ASSERT_FALSE(file.valid());
  EXPECT_EQ(hdf5_reason(), "No such file or directory");
  EXPECT_EQ(with_reason("creating a.h5"), "creating a.h5 (No such file or directory)");
}

}  // namespace
}  // namespace nebula::hdf5io

namespace nebula::hdf5io {
namespace {

// Issue 17, item 1: a library crash while reading a user's file becomes a
// one-line Error naming the file, and this process lives on.
TEST(ReadInChildFirst, ACrashBecomesAnErrorNamingTheFile) {
  try {
    read_in_child_first("damaged.h5", [] { ::raise(SIGSEGV); });
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("damaged.h5"), std::string::npos) << m;
    EXPECT_NE(m.find("crashed"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

TEST(ReadInChildFirst, TheChildsErrorIsRethrownAndSuccessReturns) {
  try {
    read_in_child_first("bad.h5", [] { throw Error("bad.h5: dataset 'x': not found"); });
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "bad.h5: dataset 'x': not found");
  }
  EXPECT_NO_THROW(read_in_child_first("good.h5", [] {}));
  // The child takes the HDF5 lock as every reader does, without deadlocking.
  EXPECT_NO_THROW(read_in_child_first("good.h5", [] { const std::lock_guard<std::mutex> lock(hdf5_mutex()); }));
}

}  // namespace
}  // namespace nebula::hdf5io
