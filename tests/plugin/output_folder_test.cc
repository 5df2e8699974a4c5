// The output folder cannot be turned against the inputs: links inside it are refused, not
// followed; one run at a time writes into it; no command writes into the photos. Every input is
// checked byte for byte afterwards.
#include <filesystem>
#include <map>
#include <string>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "tests/plugin/project_fixture.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;

// A studio project (plain backdrop: automatic masks) with the generator's exact masks.
class OutputFolder : public testing::GeneratedProject {
 protected:
  static void SetUpTestSuite() {
    MakeProject("output_folder", "--views 4 --width 96 --height 72 --points 300 --backdrop uniform");
  }
};

using testing::ExpectUserError;
using testing::FolderSnapshot;


TEST_F(OutputFolder, ALinkToTheUsersMasksInsideTheOutputIsRefusedNotFollowed) {
  // The user's masks elsewhere; an earlier carve's output folder whose masks/ became a link to
  // them: carve would have written its own masks over the user's (report.json says the folder
  // is carve's).
  const std::string masks = *root_ + "/users_masks";
  fs::copy(Project() + "/masks", masks, fs::copy_options::recursive);
  const std::string out = *root_ + "/linked_masks_out";
  std::string output;
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + out + " --resolution 16",
                &output),
            0)
      << output;
  fs::remove_all(out + "/masks");
  fs::create_directory_symlink(masks, out + "/masks");
  const auto before = FolderSnapshot(masks);
  ExpectUserError("carve --workspace_path " + Project() + " --output_path " + out + " --resolution 16",
                {out + "/masks", "symbolic link", masks});
  EXPECT_EQ(FolderSnapshot(masks), before);
  // The same with --mask_path naming them.
  ExpectUserError("carve --workspace_path " + Project() + " --output_path " + out +
                    " --resolution 16 --mask_path " + masks,
                {"symbolic link"});
  EXPECT_EQ(FolderSnapshot(masks), before);
  // A link where the mesh goes, to a user's file beside the output.
  const std::string users_file = *root_ + "/notes.ply";
  testing::WriteFile(users_file, "the user's own file\n");
  fs::remove(out + "/masks");
  fs::remove(out + "/mesh.ply");
  fs::create_symlink(users_file, out + "/mesh.ply");
  ExpectUserError("carve --workspace_path " + Project() + " --output_path " + out + " --resolution 16",
                {out + "/mesh.ply", "symbolic link"});
  EXPECT_EQ(testing::ReadFileBytes(users_file), "the user's own file\n");
}

TEST_F(OutputFolder, CalibrateHoldoutAndRenderNeverWriteIntoThePhotos) {
  const std::string photos = Project() + "/images";
  const auto before = FolderSnapshot(photos);
  // calibrate's undistorted/ a link to the photo folder.
  const std::string out = *root_ + "/calibrated";
  fs::create_directories(out);
  fs::create_directory_symlink(fs::absolute(photos), out + "/undistorted");
  ExpectUserError("calibrate --workspace_path " + Project() + " --output_path " + out,
                {out + "/undistorted", "symbolic link"});
  // holdout's folder a link to the photo folder (its images are named after the photos).
  const std::string held = *root_ + "/held";
  fs::create_directories(held);
  fs::create_directory_symlink(fs::absolute(photos), held + "/holdout");
  ExpectUserError("holdout --workspace_path " + Project() + " --output_path " + held +
                    " --resolution 16 --every 2",
                {held + "/holdout", "symbolic link"});
  // render into the photo folder.
  std::string output;
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + *root_ +
                    "/for_render --resolution 16",
                &output),
            0)
      << output;
  ExpectUserError("render --cloud_path " + *root_ + "/for_render/cloud.ply --input_path " +
                    Project() + "/sparse/0 --image_path " + photos + " --output_path " + photos,
                {"is the photo folder"});
  EXPECT_EQ(FolderSnapshot(photos), before);
}

TEST_F(OutputFolder, OneRunAtATimeWritesIntoAFolderAndAKilledRunsLockDoesNotBlock) {
  const std::string out = *root_ + "/locked";
  fs::create_directories(out);
  const std::string carve =
      "carve --workspace_path " + Project() + " --output_path " + out + " --resolution 16";
  // Another run holds the folder (this test, in its place): refused at once, naming it.
  const std::string lock = out + "/.raycarve.lock";
  const int fd = open(lock.c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(flock(fd, LOCK_EX), 0);
  const std::string pid = std::to_string(getpid());
  ASSERT_EQ(pwrite(fd, pid.data(), pid.size(), 0), static_cast<ssize_t>(pid.size()));
  ExpectUserError(carve, {out, "another raycarve run (process " + pid + ")", "--wait"});
  EXPECT_FALSE(fs::exists(out + "/report.json"));
  // Released (as when that run is killed: the kernel drops its lock), the file left behind with
  // the old process id does not block.
  close(fd);
  std::string output;
  ASSERT_EQ(Run(carve, &output), 0) << output;
  EXPECT_TRUE(fs::exists(out + "/report.json"));
  // Two carves started together with --wait: the second waits, both finish, the set is whole.
  const std::string both = "'" + testing::RaycarveBinary() + "' " + carve + " --wait > " + out +
                           "/../first.log 2>&1 & '" + testing::RaycarveBinary() + "' " + carve +
                           " --wait > " + out + "/../second.log 2>&1; second=$?; wait $!; "
                           "first=$?; echo $first $second";
  ASSERT_EQ(testing::RunShell(both, &output), 0) << output;
  EXPECT_NE(output.find("0 0"), std::string::npos)
      << output << testing::ReadFileBytes(out + "/../first.log")
      << testing::ReadFileBytes(out + "/../second.log");
  for (const char* file : {"cloud.ply", "mesh.ply", "report.json", "convergence.csv"}) {
    EXPECT_TRUE(fs::is_regular_file(out + "/" + file)) << file;
  }
  for (const auto& entry : fs::directory_iterator(out)) {
    EXPECT_EQ(entry.path().filename().string().rfind(".raycarve-partial-", 0), std::string::npos)
        << "a staging folder was left: " << entry.path();
  }
}

// A small file system of its own (tmpfs) for the output folder: needs root and a system that
// lets it mount, else the test is skipped.
class MountedFolder {
 public:
  explicit MountedFolder(const std::string& path) : path_(path) {
    fs::create_directories(path_);
    std::string output;
    mounted_ = geteuid() == 0 &&
               testing::RunShell("mount -t tmpfs -o size=4m tmpfs '" + path_ + "'", &output) == 0;
  }
  ~MountedFolder() {
    std::string output;
    if (mounted_) testing::RunShell("umount '" + path_ + "'", &output);
  }
  bool mounted() const { return mounted_; }
  // Remounts the file system read-only.
  bool MakeReadOnly() {
    std::string output;
    return testing::RunShell("mount -o remount,ro '" + path_ + "'", &output) == 0;
  }

 private:
  std::string path_;
  bool mounted_ = false;
};

TEST_F(OutputFolder, ADiskThatFillsOrTurnsReadOnlyLeavesTheEarlierOutputsWhole) {
  MountedFolder disk(*root_ + "/small_disk");
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here (needs root and CAP_SYS_ADMIN)";
  const std::string out = *root_ + "/small_disk/out";
  const std::string carve = "carve --workspace_path " + Project() + " --output_path " + out;
  std::string output;
  ASSERT_EQ(Run(carve + " --resolution 16", &output), 0) << output;
  // Every output but the lock file, which holds the last run's process id.
  const auto outputs = [&] {
    auto files = FolderSnapshot(out);
    files.erase(out + "/.raycarve.lock");
    return files;
  };
  const auto before = outputs();
  ASSERT_TRUE(before.count(out + "/cloud.ply"));
  // Fill the disk, then carve finer: larger outputs that do not fit.
  const std::string filler = *root_ + "/small_disk/filler";
  testing::RunShell("dd if=/dev/zero of='" + filler + "' bs=64k 2> /dev/null", &output);
  ExpectUserError(carve + " --resolution 48",
                  {"No space left on device", "nothing was replaced in " + out,
                   "the outputs already there are as they were"});
  EXPECT_EQ(outputs(), before);
  fs::remove(filler);
  // The same disk read-only: the run cannot even take the folder's lock or stage; nothing changes.
  ASSERT_TRUE(disk.MakeReadOnly());
  ExpectUserError(carve + " --resolution 48", {out, "Read-only file system"});
  EXPECT_EQ(outputs(), before);
}

TEST_F(OutputFolder, FilesystemFailuresAreInputErrorsNamingThePath) {
  // Permissions bind only an unprivileged user: as root, each command runs as nobody (setpriv).
  std::string as_user;
  if (geteuid() == 0) {
    if (!fs::exists("/usr/bin/setpriv")) GTEST_SKIP() << "running as root without setpriv";
    as_user = "/usr/bin/setpriv --reuid=65534 --regid=65534 --clear-groups ";
  }
  const std::string place = *root_ + "/unprivileged";
  fs::create_directories(place);
  const std::string binary = place + "/raycarve";
  fs::copy_file(testing::RaycarveBinary(), binary);
  const std::string project = place + "/project";
  fs::copy(Project(), project, fs::copy_options::recursive);
  for (const auto& entry : fs::recursive_directory_iterator(place)) {
    fs::permissions(entry.path(), fs::perms::others_read | fs::perms::group_read, fs::perm_options::add);
    if (entry.is_directory()) {
      fs::permissions(entry.path(), fs::perms::others_exec | fs::perms::group_exec, fs::perm_options::add);
    }
  }
  fs::permissions(*root_, fs::perms::all, fs::perm_options::add);
  fs::permissions(place, fs::perms::all, fs::perm_options::add);
  const auto run = [&](const std::string& arguments, std::initializer_list<std::string> parts) {
    std::string output;
    EXPECT_EQ(testing::RunShell(as_user + "'" + binary + "' " + arguments, &output), 1)
        << arguments << "\n" << output;
    for (const std::string& part : parts) {
      EXPECT_NE(output.find(part), std::string::npos) << "'" << part << "' not in:\n" << output;
    }
    EXPECT_EQ(output.find("unexpected error"), std::string::npos) << output;
  };
  const std::string carve = "carve --workspace_path " + project + " --resolution 16 --output_path ";
  // An unreadable photo folder, then one unreadable photo.
  fs::permissions(project + "/images", fs::perms::none);
  run(carve + place + "/out1", {project + "/images", "ermission denied"});
  fs::permissions(project + "/images", fs::perms::owner_all | fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(project + "/images/view001.png", fs::perms::none);
  run(carve + place + "/out2", {project + "/images/view001.png", "ermission denied"});
  fs::permissions(project + "/images/view001.png", fs::perms::owner_read | fs::perms::others_read);
  // An output folder that cannot be made, for each command that writes.
  const std::string read_only = place + "/read_only";
  fs::create_directories(read_only);
  fs::permissions(read_only, fs::perms::owner_all | fs::perms::others_read | fs::perms::others_exec);
  run(carve + read_only + "/out", {read_only + "/out", "ermission denied"});
  run("calibrate --workspace_path " + project + " --output_path " + read_only + "/out",
      {read_only + "/out", "ermission denied"});
  run("compare --reference_path " + project + "/truth.ply --input_path " + project +
          "/truth.ply --output_path " + read_only + "/compare.json",
      {read_only, "ermission denied"});
  // A link loop as the workspace; a name longer than the filesystem allows as the output.
  fs::create_symlink(place + "/loop_b", place + "/loop_a");
  fs::create_symlink(place + "/loop_a", place + "/loop_b");
  run("carve --workspace_path " + place + "/loop_a", {place + "/loop_a", "symbolic links"});
  run(carve + place + "/" + std::string(300, 'x'), {"File name too long"});
}

TEST_F(OutputFolder, CompareRefusesSampleCountsBeyondTheMachinesMemory) {
  std::string output;
  EXPECT_EQ(Run("compare --reference_path " + Project() + "/truth.ply --input_path " + Project() +
                    "/truth.ply --mesh_samples 2000000000",
                &output),
            1)
      << output;
  EXPECT_NE(output.find("--mesh_samples 2000000000"), std::string::npos) << output;
  EXPECT_NE(output.find("give at most"), std::string::npos) << output;
}

}  // namespace
}  // namespace raycarve
