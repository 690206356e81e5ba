// Issue 21: a disk that fills during a run (a small tmpfs mounted for the
// test; skipped where mounting is not allowed). The run used to end in a
// segmentation fault inside MPI_Finalize (HDF5 1.10 closing again a file
// whose close had failed) after pages of HDF5 diagnostics, never saying the
// disk was full. Now: exit 1, one error line naming the file and "No space
// left on device", no HDF5 diagnostics, and the previous checkpoint, when
// there is one, intact and readable.
#include <gtest/gtest.h>
#include <sys/mount.h>

#include <cerrno>
#include <cstring>

#include "kernels/error.hpp"
#include "runtime/checkpoint.hpp"
#include "runtime/model.hpp"
#include "scene_text.hpp"
#include "shatter_cli.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kScene =
    shatter::test::steel_box_scene("full_disk", "0.0012", "", "checkpoint: {every_steps: 3}\n");

}  // namespace

TEST(FullDisk, RunEndsWithOneMessageAndKeepsThePreviousCheckpoint) {
  const fs::path mnt = shatter::test::scratch_dir("full_disk_mount");
  const std::string scene = shatter::test::write_scene("full_disk", kScene);
  const shatter::Model model = shatter::build_model(shatter::load_scene(scene));
  int runs = 0;
  // Sizes at which the fields, then the checkpoints, run out of room.
  for (const char* size : {"1100k", "2m", "2500k", "3m", "4m"}) {
    if (mount("tmpfs", mnt.c_str(), "tmpfs", 0, (std::string("size=") + size).c_str()) != 0)
      GTEST_SKIP() << "cannot mount a tmpfs here: " << std::strerror(errno);
    const fs::path out = mnt / "out";
    const auto r = shatter::test::run_shatter("run " + scene + " --quiet --out " + out.string());
    EXPECT_EQ(r.status, 1) << size << ": " << r.output;
    EXPECT_EQ(r.output.rfind("error: ", 0), 0u) << size << ": " << r.output;
    EXPECT_NE(r.first_line().find("No space left on device"), std::string::npos) << size << ": " << r.output;
    const bool fields = r.output.rfind("error: fields output " + (out / "fields.h5").string() + ": ", 0) == 0;
    const bool checkpoint = r.output.rfind("error: checkpoint " + (out / "checkpoint.h5.tmp").string() + ": ", 0) == 0;
    EXPECT_TRUE(fields || checkpoint) << size << ": " << r.output;
    EXPECT_EQ(r.output.find("HDF5-DIAG"), std::string::npos) << size << ": " << r.output;
    EXPECT_EQ(r.output.find("Segmentation"), std::string::npos) << size << ": " << r.output;
    EXPECT_FALSE(fs::exists(out / "checkpoint.h5.tmp")) << size;
    EXPECT_FALSE(fs::exists(out / ".shatter_reserve")) << size;
    if (fs::exists(out / "checkpoint.h5")) {
      EXPECT_GT(shatter::read_checkpoint(out / "checkpoint.h5", model).step, 0) << size;
    }
    umount(mnt.c_str());
    ++runs;
  }
  EXPECT_EQ(runs, 5);
}
