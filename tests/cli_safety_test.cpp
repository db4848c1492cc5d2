// The fogcl CLI never loses a file and fails in one clear line: outputs that would replace an input
// or another output (by device and inode: links and other spellings count), destinations that are
// not regular files, the mode and group of a rewritten output, a frame's EXR and PNG committed
// together, named temporaries removed on SIGINT / SIGTERM and swept after a kill, long output
// names, and the message and exit code of each misuse (1 for a rule, 2 for a usage error).
#include <fcntl.h>
#include <grp.h>
#include <limits.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <thread>
#include <vector>

#include "fogcl/demo_scene.h"
#include "fogcl/exr_io.h"
#include "io/atomic_file.h"
#include "test_support.h"

namespace fogcl::test {
namespace {

namespace fs = std::filesystem;


int lines(const std::string& s) { return int(std::count(s.begin(), s.end(), '\n')); }

std::vector<std::string> temporaries_in(const std::string& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) found.push_back(e.path().filename().string());
  return found;
}

std::string host_tag() {
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  return host;
}

const std::string kNoFov = " --near 0.3 --far 1000 --mode exp2 --density 0.03 --device scalar";
const std::string kFog = kNoFov + " --fov 60";

class CliSafety : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    base_ = fresh_dir("cli-safety");
    PerspectiveCamera camera;
    camera.fov_y_deg = 60.0f;
    const DemoFrame frame = render_demo_scene(64, 36, camera, DemoView{});
    write_exr_rgba(base_ + "/color.exr", frame.color);
    write_exr_depth(base_ + "/depth.exr", frame.depth);
    write_text(base_ + "/volumes.json", R"({"volumes": [{"center": [0, 1, 4], "radius": 2}]})");
    write_text(base_ + "/shadow.exr", read_text(base_ + "/depth.exr"));
  }
  static void TearDownTestSuite() { fs::remove_all(base_); }
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = base_ + "/" + info->name();
    fs::create_directories(dir_);
    for (const char* f : {"color.exr", "depth.exr", "volumes.json", "shadow.exr"})
      fs::copy_file(base_ + "/" + f, dir_ + "/" + f);
  }
  std::string path(const std::string& name) const { return dir_ + "/" + name; }
  // apply on this test's color + depth.
  std::string apply(const std::string& more) const {
    return "apply --color " + path("color.exr") + " --depth " + path("depth.exr") + kFog + " " + more;
  }
  // The same without --fov.
  std::string apply_no_fov(const std::string& more) const {
    return "apply --color " + path("color.exr") + " --depth " + path("depth.exr") + kNoFov + " " + more;
  }
  std::string volume_flags() const {
    return " --volumes " + path("volumes.json") + " --eye 0,1.6,-6 --forward 0,0,1 --up 0,1,0";
  }
  static inline std::string base_;
  std::string dir_;
};

// Every pair of an output and an input (or another output), each spelled as given, through a
// symbolic link, a hard link and another spelling: refused with one line, exit 1, the file intact.
TEST_F(CliSafety, AnOutputThatIsAnInputOrAnotherOutputIsRefused) {
  fs::create_symlink(path("color.exr"), path("link-to-color.exr"));
  fs::create_symlink(path("depth.exr"), path("link-to-depth.exr"));
  fs::create_hard_link(path("depth.exr"), path("hard-depth.exr"));
  fs::create_hard_link(path("volumes.json"), path("hard-volumes.json"));
  write_text(path("old-out.exr"), read_text(path("color.exr")));
  fs::create_hard_link(path("old-out.exr"), path("hard-old-out.exr"));
  const std::string shadow = " --shadow-map " + path("shadow.exr") + " --light-view-proj 1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1";
  const std::string rel = fs::relative(path("depth.exr")).string();
  const struct {
    std::string args, says, protects;
  } cases[] = {
      {"--out " + path("depth.exr"), "--out '" + path("depth.exr") + "' is the same file as --depth", "depth.exr"},
      {"--out " + path("volumes.json") + volume_flags(), "is the same file as --volumes", "volumes.json"},
      {"--out " + path("shadow.exr") + volume_flags() + shadow, "is the same file as --shadow-map", "shadow.exr"},
      {"--out " + path("o.exr") + " --png " + path("color.exr"), "--png '" + path("color.exr") + "' is the same file as --color",
       "color.exr"},
      {"--out " + path("o.exr") + " --png " + path("depth.exr"), "is the same file as --depth", "depth.exr"},
      {"--out " + path("o.exr") + " --png " + path("volumes.json") + volume_flags(), "is the same file as --volumes",
       "volumes.json"},
      {"--out " + path("old-out.exr") + " --png " + path("old-out.exr"), "is the same file as --out", "old-out.exr"},
      // Not by spelling: links and another path to the same file.
      {"--out " + path("o.exr") + " --png " + path("link-to-color.exr"), "is the same file as --color", "color.exr"},
      {"--out " + path("link-to-depth.exr"), "is the same file as --depth", "depth.exr"},
      {"--out " + path("hard-depth.exr"), "is the same file as --depth", "depth.exr"},
      {"--out " + path("hard-volumes.json") + volume_flags(), "is the same file as --volumes", "volumes.json"},
      {"--out " + path("old-out.exr") + " --png " + path("hard-old-out.exr"), "is the same file as --out",
       "old-out.exr"},
      {"--out " + rel, "is the same file as --depth", "depth.exr"},
      {"--out " + dir_ + "/../" + fs::path(dir_).filename().string() + "/depth.exr", "is the same file as --depth",
       "depth.exr"},
      // Two outputs that do not exist yet, spelled differently.
      {"--out " + path("new.exr") + " --png " + dir_ + "/./new.exr", "is the same file as --out", ""},
  };
  for (const auto& c : cases) {
    const std::string before = c.protects.empty() ? "" : read_text(path(c.protects));
    const CliRun r = run_cli(apply(c.args));
    std::printf("[ refused  ] %s", r.output.c_str());
    EXPECT_EQ(r.exit_code, 1) << c.args << "\n" << r.output;
    EXPECT_EQ(lines(r.output), 1) << c.args << "\n" << r.output;
    EXPECT_EQ(r.output.rfind("fogcl: error: ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << "\n" << r.output;
    if (!c.protects.empty()) {
      EXPECT_TRUE(read_text(path(c.protects)) == before) << c.protects << " changed";
    }
    EXPECT_FALSE(fs::exists(path("o.exr")));
    EXPECT_FALSE(fs::exists(path("new.exr")));
  }
  EXPECT_TRUE(fs::is_symlink(path("link-to-depth.exr")));
  EXPECT_TRUE(temporaries_in(dir_).empty());
}

// The same per frame of a sequence: the frame that would replace its input fails before it is
// read; fogging the color frames in place stays allowed.
TEST_F(CliSafety, ASequenceFrameThatWouldReplaceAnInputIsRefused) {
  fs::copy_file(path("color.exr"), path("c.0001.exr"));
  fs::copy_file(path("depth.exr"), path("d.0001.exr"));
  const std::string depth = read_text(path("d.0001.exr"));
  const std::string seq = "apply --color " + path("c.####.exr") + " --depth " + path("d.####.exr") + kFog;
  const struct {
    std::string args, says;
  } cases[] = {
      {" --out " + path("d.####.exr"), "frame 1: --out '" + path("d.0001.exr") + "' is the same file as --depth"},
      {" --out " + path("o.####.exr") + " --png " + path("o.%04d.exr"),
       "frame 1: --png '" + path("o.0001.exr") + "' is the same file as --out"},
  };
  for (const auto& c : cases) {
    const CliRun r = run_cli(seq + c.args);
    std::printf("[ refused  ] %s", r.output.c_str());
    EXPECT_EQ(r.exit_code, 1) << c.args << "\n" << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << "\n" << r.output;
    EXPECT_TRUE(read_text(path("d.0001.exr")) == depth) << "the depth frame changed";
    EXPECT_FALSE(fs::exists(path("o.0001.exr")));
  }
  const std::string color = read_text(path("c.0001.exr"));
  const CliRun r = run_cli(seq + " --out " + path("c.####.exr"));
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(read_text(path("c.0001.exr")), color) << "the color frame was not fogged in place";
}

// Fogging --color in place stays allowed, also through a link; a link as --out is written
// through (the file it names is replaced, the link stays).
TEST_F(CliSafety, FoggingColorInPlaceStaysAllowed) {
  const std::string before = read_text(path("color.exr"));
  CliRun r = run_cli("apply --color " + path("color.exr") + " --depth " + path("depth.exr") + kFog + " --out " +
                     path("color.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string once = read_text(path("color.exr"));
  EXPECT_NE(once, before) << "the color file was not fogged in place";
  fs::create_symlink(path("color.exr"), path("link.exr"));
  r = run_cli("apply --color " + path("color.exr") + " --depth " + path("depth.exr") + kFog + " --out " +
              path("link.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::is_symlink(path("link.exr")));
  EXPECT_NE(read_text(path("color.exr")), once) << "the file the link names was not fogged";
  EXPECT_TRUE(temporaries_in(dir_).empty());
}

// The whole sequence before its first frame: an output of one frame that is the input of another
// frame (by name, symbolic link, hard link, or a link not yet resolvable), or two outputs that are
// one file, refuse the run in one line naming both files, and nothing is read or written.
TEST_F(CliSafety, ASequenceOutputThatIsAnotherFramesFileIsRefusedBeforeAnyFrame) {
  fs::create_directories(path("seq"));
  const auto in = [&](const std::string& name) { return path("seq/" + name); };
  for (int f = 1; f <= 10; ++f) {
    char num[8];
    std::snprintf(num, sizeof num, "%04d", f);
    fs::copy_file(path("color.exr"), in("color." + std::string(num) + ".exr"));
    fs::copy_file(path("depth.exr"), in("depth." + std::string(num) + ".exr"));
  }
  fs::create_symlink("color.0002.exr", in("x.0001.exr"));  // frame 1's output would be frame 2's input
  fs::create_hard_link(in("depth.0005.exr"), in("h.0003.exr"));
  write_text(in("o.0001.exr"), "an earlier output");
  fs::create_symlink("o.0001.exr", in("o.0002.exr"));   // two frames, one output file
  fs::copy_file(path("depth.exr"), in("dm.0001.exr"));  // dm.0002.exr does not exist yet
  fs::create_symlink("dm.0002.exr", in("n.0001.exr"));
  const struct {
    std::string args, says;
  } cases[] = {
      {" --out " + in("color.%03d0.exr"), "frame 1: --out '" + in("color.0010.exr") + "' is the same file as --color '" +
                                              in("color.0010.exr") + "' of frame 10: writing it would replace that input"},
      {" --frames 1-2 --out " + in("x.####.exr"),
       "frame 1: --out '" + in("x.0001.exr") + "' is the same file as --color '" + in("color.0002.exr") + "' of frame 2"},
      {" --out " + in("h.####.exr"),
       "frame 3: --out '" + in("h.0003.exr") + "' is the same file as --depth '" + in("depth.0005.exr") + "' of frame 5"},
      {" --frames 1-2 --out " + in("o.####.exr"), "frame 2: --out '" + in("o.0002.exr") + "' is the same file as --out '" +
                                                       in("o.0001.exr") + "' of frame 1: one output would replace the other"},
      {" --out " + in("q.####.exr") + " --png " + in("q.%03d0.exr"),
       "frame 10: --out '" + in("q.0010.exr") + "' is the same file as --png '" + in("q.0010.exr") + "' of frame 1"},
      {" --out " + in("p.####.exr") + " --png " + in("p.%04d.exr"),
       "frame 1: --png '" + in("p.0001.exr") + "' is the same file as --out '" + in("p.0001.exr") + "'"},
      // A file that does not exist yet: frame 1 would create the depth file frame 2 then reads.
      {" --frames 1-2 --out " + in("n.####.exr") + " --depth " + in("dm.####.exr") + " --color " + in("color.####.exr"),
       "frame 1: --out '" + in("n.0001.exr") + "' is the same file as --depth '" + in("dm.0002.exr") + "' of frame 2"},
      // A --depth without placeholder is every frame's input: no frame may fog it in place.
      {" --frames 1-2 --out " + in("color.####.exr") + " --depth " + in("color.0002.exr") + " --color " +
           in("color.####.exr"),
       "frame 2: --out '" + in("color.0002.exr") + "' is the same file as --depth '" + in("color.0002.exr") +
           "' (read by every frame)"},
  };
  std::vector<std::pair<std::string, std::string>> before;
  for (const auto& e : fs::directory_iterator(path("seq")))
    before.push_back({e.path().filename().string(), fs::is_symlink(e.symlink_status()) ? "link" : read_text(e.path())});
  std::sort(before.begin(), before.end());
  for (const auto& c : cases) {
    // A case with its own --depth gives its --color too.
    const std::string files = c.args.find(" --depth ") != std::string::npos
                                  ? std::string()
                                  : " --color " + in("color.####.exr") + " --depth " + in("depth.####.exr");
    const CliRun r = run_cli("apply" + files + kFog + c.args);
    std::printf("[ refused  ] %s", r.output.c_str());
    EXPECT_EQ(r.exit_code, 1) << c.args << "\n" << r.output;
    EXPECT_EQ(lines(r.output), 1) << c.args << "\n" << r.output;
    EXPECT_EQ(r.output.rfind("fogcl: error: ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << "\n" << r.output;
    std::vector<std::pair<std::string, std::string>> after;
    for (const auto& e : fs::directory_iterator(path("seq")))
      after.push_back({e.path().filename().string(), fs::is_symlink(e.symlink_status()) ? "link" : read_text(e.path())});
    std::sort(after.begin(), after.end());
    EXPECT_TRUE(after == before) << c.args << ": a file of the folder was written, replaced or created";
  }
}

// Fogging each frame in place stays allowed, and gives the bytes of a run into other files.
TEST_F(CliSafety, ASequenceFoggedInPlaceGivesTheBytesOfARunIntoOtherFiles) {
  for (int f = 1; f <= 3; ++f) {
    const std::string n = "000" + std::to_string(f);
    fs::copy_file(path("color.exr"), path("c." + n + ".exr"));
    fs::copy_file(path("depth.exr"), path("d." + n + ".exr"));
  }
  const std::string seq = "apply --color " + path("c.####.exr") + " --depth " + path("d.####.exr") + kFog;
  CliRun r = run_cli(seq + " --out " + path("ref.####.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  r = run_cli(seq + " --out " + path("c.%04d.exr"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (int f = 1; f <= 3; ++f) {
    const std::string n = "000" + std::to_string(f);
    const std::string fogged = read_text(path("c." + n + ".exr"));
    EXPECT_NE(fogged, read_text(path("color.exr"))) << "frame " << f << " was not fogged";
    EXPECT_TRUE(fogged == read_text(path("ref." + n + ".exr"))) << "frame " << f << " differs from its fog into ref";
  }
  EXPECT_TRUE(temporaries_in(dir_).empty());
}

// Inputs that are not regular files (a character device, a directory, a FIFO) are refused before
// they are opened, in one line naming the flag, the file and what it is. The runs have a time
// limit so that a FIFO opened by mistake fails the test instead of hanging it.
TEST_F(CliSafety, AnInputThatIsNotARegularFileIsRefusedBeforeItIsOpened) {
  ASSERT_EQ(::mkfifo(path("in.fifo").c_str(), 0644), 0);
  fs::create_directories(path("in-folder"));
  fs::create_directories(path("seq"));
  fs::copy_file(path("color.exr"), path("seq/c.0001.exr"));
  ASSERT_EQ(::mkfifo(path("seq/c.0002.exr").c_str(), 0644), 0);
  const std::string pose = " --eye 0,1.6,-6 --forward 0,0,1 --up 0,1,0";
  const std::string out = " --out " + path("o.exr");
  const struct {
    std::string args, says;
  } cases[] = {
      {"apply --color /dev/zero" + kFog + out, "--color '/dev/zero': is a character device, not a regular file"},
      {"apply --color " + path("in.fifo") + kFog + out, "--color '" + path("in.fifo") + "': is a FIFO (named pipe), not a regular file"},
      {"apply --color " + path("in-folder") + kFog + out, "--color '" + path("in-folder") + "': is a directory"},
      {apply("--volumes /dev/zero" + pose + out), "--volumes '/dev/zero': is a character device, not a regular file"},
      {apply("--volumes " + path("in.fifo") + pose + out), "--volumes '" + path("in.fifo") + "': is a FIFO (named pipe)"},
      {apply("--volumes " + path("in-folder") + pose + out), "--volumes '" + path("in-folder") + "': is a directory"},
      {"apply --color " + path("color.exr") + " --depth " + path("in.fifo") + kFog + out, "--depth '" + path("in.fifo") + "': is a FIFO"},
      {"apply --color " + path("seq/c.####.exr") + " --depth " + path("depth.exr") + kFog + " --out " + path("seq/o.####.exr"),
       "frame 2: --color '" + path("seq/c.0002.exr") + "': is a FIFO (named pipe), not a regular file"},
  };
  for (const auto& c : cases) {
    const CliRun r = run_cli(c.args, "timeout -s KILL 120");
    std::printf("[ refused  ] %s", r.output.c_str());
    EXPECT_EQ(r.exit_code, 1) << c.args << "\n" << r.output;
    EXPECT_EQ(lines(r.output), 1) << c.args << "\n" << r.output;
    EXPECT_EQ(r.output.rfind("fogcl: error: ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << "\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(path("o.exr")));
}

// The library's reader refuses a FIFO without opening it. A writer waits on the FIFO meanwhile, so
// a reader that opened it would get an empty stream (and another message) instead of hanging; the
// writer is then released by opening the read end here.
TEST_F(CliSafety, TheExrReaderRefusesAFifoWithoutOpeningIt) {
  const std::string fifo = path("r.fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);  // blocks until a reader opens
    if (fd >= 0) ::close(fd);
  });
  std::string message;
  try {
    read_exr(fifo, ExrReadRequest{});
  } catch (const Error& e) {
    message = e.what();
  }
  const int release = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  writer.join();
  if (release >= 0) ::close(release);
  std::printf("[ fifo     ] %s\n", message.c_str());
  EXPECT_EQ(message, fifo + ": cannot read EXR: it is a FIFO (named pipe), not a regular file");
}

// A destination that exists and is not a regular file is refused, never replaced.
TEST_F(CliSafety, ADestinationThatIsNotARegularFileIsRefused) {
  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0644), 0);
  fs::create_directories(path("folder.exr"));
  fs::create_symlink(path("missing.exr"), path("dangling.exr"));
  const int sock = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  const std::string sock_path = path("sock");
  const bool have_socket = sock >= 0 && sock_path.size() < sizeof addr.sun_path &&
                           (std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", sock_path.c_str()),
                            ::bind(sock, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0);
  struct Case {
    std::string args, says;
  };
  std::vector<Case> cases = {
      {"--out " + path("fifo"), "--out '" + path("fifo") + "': it is a FIFO (named pipe), not a regular file"},
      {"--out " + path("o.exr") + " --png " + path("fifo"), "--png '" + path("fifo") + "': it is a FIFO"},
      {"--out " + path("folder.exr"), "it is a directory"},
      {"--out " + path("dangling.exr"), "it is a symbolic link to '" + path("missing.exr") + "', which does not exist"},
      {"--out " + path("no-such-folder/o.exr"), "the folder '" + path("no-such-folder") + "' does not exist"},
      {"--out " + path("color.exr/o.exr"), "'" + path("color.exr") + "' is not a folder"},
  };
  if (have_socket) cases.push_back({"--out " + path("sock"), "it is a socket"});
  const bool root = ::geteuid() == 0;
  if (root) {  // a device node: what replaced /dev/null before
    ASSERT_EQ(::mknod(path("null").c_str(), S_IFCHR | 0666, makedev(1, 3)), 0);
    cases.push_back({"--out " + path("null"), "it is a character device"});
  }
  for (const Case& c : cases) {
    const CliRun r = run_cli(apply(c.args));
    std::printf("[ refused  ] %s", r.output.c_str());
    EXPECT_EQ(r.exit_code, 1) << c.args << "\n" << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << "\n" << r.output;
  }
  struct stat st {};
  ASSERT_EQ(::stat(path("fifo").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  if (root) {
    ASSERT_EQ(::stat(path("null").c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
  } else {
    std::printf("[ skipped  ] the device node case needs root (mknod)\n");
  }
  if (sock >= 0) ::close(sock);
  EXPECT_TRUE(fs::is_directory(path("folder.exr")));
  EXPECT_FALSE(fs::exists(path("o.exr")));
  EXPECT_TRUE(temporaries_in(dir_).empty());
}

// A rewritten output keeps its mode and group, with unnamed and with named temporaries.
TEST_F(CliSafety, ARewrittenOutputKeepsItsModeAndGroup) {
  // A group other than ours: any as root, else a supplementary group if the user has one.
  gid_t other = ::getegid();
  if (::geteuid() == 0) {
    other = ::getegid() == 4242 ? 4243 : 4242;
  } else {
    std::vector<gid_t> groups(std::size_t(std::max(0, ::getgroups(0, nullptr))));
    if (!groups.empty() && ::getgroups(int(groups.size()), groups.data()) >= 0)
      for (gid_t g : groups)
        if (g != ::getegid()) other = g;
  }
  for (const char* mode : {"", "FOGCL_TEMP_FILES=named"}) {
    SCOPED_TRACE(*mode ? mode : "unnamed temporaries");
    const std::string out = path(std::string("kept") + (*mode ? "-named" : "") + ".exr");
    const std::string png = path(std::string("kept") + (*mode ? "-named" : "") + ".png");
    for (const std::string& f : {out, png}) {
      write_text(f, "old");
      ASSERT_EQ(::chmod(f.c_str(), 0640), 0);
      if (other != ::getegid()) {
        ASSERT_EQ(::chown(f.c_str(), uid_t(-1), other), 0);
      }
    }
    const CliRun r = run_cli(apply("--out " + out + " --png " + png), mode);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const std::string& f : {out, png}) {
      struct stat st {};
      ASSERT_EQ(::stat(f.c_str(), &st), 0);
      std::printf("[ kept     ] %s: mode %04o (want 0640), group %d (want %d)\n", fs::path(f).filename().c_str(),
                  unsigned(st.st_mode & 07777), int(st.st_gid), int(other));
      EXPECT_EQ(st.st_mode & 07777, 0640u) << f;
      EXPECT_EQ(st.st_gid, other) << f;
      EXPECT_NE(read_text(f), "old") << f << " was not rewritten";
    }
  }
  if (other == ::getegid()) std::printf("[ skipped  ] the group case: this user has no second group\n");
}

// A frame's EXR and PNG are committed together: a preview that cannot be written leaves the EXR's
// destination as it was, whether the folder is missing (found before any work) or the file system
// refuses the file once both are written (the batch: nothing is committed).
TEST_F(CliSafety, AFailedPreviewLeavesTheExrDestinationUntouched) {
  for (const char* mode : {"", "FOGCL_TEMP_FILES=named"}) {
    SCOPED_TRACE(*mode ? mode : "unnamed temporaries");
    write_text(path("out.exr"), "the previous output");
    CliRun r = run_cli(apply("--out " + path("out.exr") + " --png " + path("missing/p.png")), mode);
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find("the folder '" + path("missing") + "' does not exist"), std::string::npos) << r.output;
    EXPECT_EQ(read_text(path("out.exr")), "the previous output");
    // /proc takes no new file: the PNG fails when it is prepared, after the EXR was.
    r = run_cli(apply("--out " + path("out.exr") + " --png /proc/fogcl-safety-test.png"), mode);
    std::printf("[ refused  ] %s", r.output.c_str());
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find("/proc/fogcl-safety-test.png: cannot write PNG"), std::string::npos) << r.output;
    EXPECT_EQ(read_text(path("out.exr")), "the previous output");
    EXPECT_TRUE(temporaries_in(dir_).empty());
    // In place: a rerun after such a failure must not fog twice.
    const std::string color = read_text(path("color.exr"));
    r = run_cli("apply --color " + path("color.exr") + " --depth " + path("depth.exr") + kFog + " --out " +
                    path("color.exr") + " --png /proc/fogcl-safety-test.png",
                mode);
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_TRUE(read_text(path("color.exr")) == color) << "the color file was fogged although the run failed";
  }
}

// The batch itself: the second file fails, the first is not committed; both commit together.
TEST_F(CliSafety, AWriteBatchCommitsAllOrNothing) {
  for (const bool named : {false, true}) {
    SCOPED_TRACE(named ? "named temporaries" : "unnamed temporaries");
    if (named) ::setenv("FOGCL_TEMP_FILES", "named", 1);
    const auto write = [](const std::string& p, const std::string& text) {
      detail::write_file_atomically(p, "TEXT", [&](std::ostream& out, const std::string&) { out << text; });
    };
    write_text(path("a.txt"), "old a");
    try {
      detail::WriteBatch batch;
      write(path("a.txt"), "new a");
      EXPECT_EQ(read_text(path("a.txt")), "old a") << "replaced before the commit";
      write(path("missing/b.txt"), "new b");
      batch.commit();
      ADD_FAILURE() << "the second write did not fail";
    } catch (const Error& e) {
      std::printf("[ failed   ] %s\n", e.what());
      EXPECT_NE(std::string(e.what()).find("the folder '" + path("missing") + "' does not exist"), std::string::npos)
          << e.what();
    }
    EXPECT_EQ(read_text(path("a.txt")), "old a");
    EXPECT_TRUE(temporaries_in(dir_).empty());
    {
      detail::WriteBatch batch;
      write(path("a.txt"), "new a");
      write(path("b.txt"), "new b");
      batch.commit();
    }
    EXPECT_EQ(read_text(path("a.txt")), "new a");
    EXPECT_EQ(read_text(path("b.txt")), "new b");
    EXPECT_TRUE(temporaries_in(dir_).empty());
    fs::remove(path("b.txt"));
    ::unsetenv("FOGCL_TEMP_FILES");
  }
}

// Named temporaries (the NFS mode) get names within NAME_MAX for long output names; a single-file
// run sweeps the stale ones of its own outputs as a sequence does, and leaves others alone.
TEST_F(CliSafety, NamedTemporariesFitLongNamesAndSingleFilesSweepTheirOwn) {
  const std::string long_name = std::string(246, 'n') + ".exr";  // 250 bytes
  ASSERT_EQ(long_name.size(), 250u);
  CliRun r = run_cli(apply("--out " + path(long_name)), "FOGCL_TEMP_FILES=named");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_TRUE(fs::exists(path(long_name)));
  const std::string key = detail::temporary_key(long_name);
  const std::string longest_temp = key + ".tmp-" + std::string(64, 'h') + "-4294967295-18446744073709551615";
  std::printf("[ measured ] a 250-byte name's temporary key: %zu bytes; longest temporary name %zu bytes (NAME_MAX %d)\n",
              key.size(), longest_temp.size(), NAME_MAX);
  EXPECT_LE(longest_temp.size(), std::size_t(NAME_MAX));
  EXPECT_EQ(detail::temporary_key("short.exr"), "short.exr");
  EXPECT_NE(detail::temporary_key(std::string(246, 'n') + ".png"), key);  // the hash tells them apart

  // Stale temporaries of a killed writer (pid 2^22 + 1: above Linux's default pid_max).
  const std::string dead = "-" + host_tag() + "-4194305-0";
  const std::string mine = "o.exr.tmp" + dead, mine_png = "o.png.tmp" + dead, mine_long = key + ".tmp" + dead;
  const std::string other = "other.exr.tmp" + dead, remote = "o.exr.tmp-some-other-host-4194305-0";
  for (const std::string& f : {mine, mine_png, mine_long, other, remote}) write_text(path(f), "partial");
  r = run_cli(apply("--verbose --out " + path("o.exr") + " --png " + path("o.png")), "FOGCL_TEMP_FILES=named");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("removed 2 stale temporary file(s)"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path(mine)));
  EXPECT_FALSE(fs::exists(path(mine_png)));
  EXPECT_TRUE(fs::exists(path(mine_long)));  // another output's
  EXPECT_TRUE(fs::exists(path(other)));
  EXPECT_TRUE(fs::exists(path(remote)));  // another machine's: maybe still writing
  r = run_cli(apply("--verbose --out " + path(long_name)), "FOGCL_TEMP_FILES=named");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("removed 1 stale temporary file(s)"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path(mine_long)));

  // A sequence whose frame names are too long to appear whole: its shortened temporaries are
  // known by their leading bytes (the stem, then digits); another sequence's stay.
  fs::create_directories(path("seq"));
  fs::copy_file(path("color.exr"), path("seq/c.0001.exr"));
  fs::copy_file(path("depth.exr"), path("seq/d.0001.exr"));
  const std::string stem = std::string(120, 's') + ".";
  const std::string frame_name = stem + "0001" + std::string(120, 'x') + ".exr";
  const std::string seq_temp = detail::temporary_key(frame_name) + ".tmp" + dead;
  const std::string others = detail::temporary_key(std::string(120, 't') + ".0001" + std::string(120, 'x') + ".exr") +
                             ".tmp" + dead;
  ASSERT_NE(detail::temporary_key(frame_name), frame_name);
  for (const std::string& f : {seq_temp, others}) write_text(path("seq/" + f), "partial");
  r = run_cli("apply --color " + path("seq/c.####.exr") + " --depth " + path("seq/d.####.exr") + kFog +
                  " --verbose --out " + path("seq/" + stem + "####" + std::string(120, 'x') + ".exr"),
              "FOGCL_TEMP_FILES=named");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("removed 1 stale temporary file(s)"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(path("seq/" + seq_temp)));
  EXPECT_TRUE(fs::exists(path("seq/" + others)));
  EXPECT_TRUE(fs::exists(path("seq/" + frame_name)));
}

// ---- Signals with named temporaries ------------------------------------------------------------

// The files in `dir`, sorted.
std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir)) found.push_back(e.path().filename().string());
  std::sort(found.begin(), found.end());
  return found;
}

// Each signal lands while an output is being written: the run is held (tests/support/call_gate.c)
// at the rename that names frame 3's EXR, its PNG's temporary written too. The next signal is sent
// once the handler of the one before has returned (two pending SIGINTs would merge into one).
TEST_F(CliSafety, SignalsLeaveNoNamedTemporary) {
  fs::create_directories(path("in"));
  fs::create_directories(path("out"));
  for (int f = 1; f <= 8; ++f) {
    DemoView view;
    view.eye.z += 0.1f * float(f);
    PerspectiveCamera camera;
    camera.fov_y_deg = 60.0f;
    const DemoFrame frame = render_demo_scene(96, 54, camera, view);
    char name[64];
    std::snprintf(name, sizeof name, "in/color.%04d.exr", f);
    write_exr_rgba(path(name), frame.color);
    std::snprintf(name, sizeof name, "in/depth.%04d.exr", f);
    write_exr_depth(path(name), frame.depth);
  }
  const std::string sequence = "apply --color " + path("in/color.####.exr") + " --depth " + path("in/depth.####.exr") +
                               kFog + " --threads 1 --out " + path("out/o.####.exr") + " --png " + path("out/o.####.png");
  const std::string single = "apply --color " + path("in/color.0003.exr") + " --depth " + path("in/depth.0003.exr") +
                             kFog + " --threads 1 --out " + path("out/o.0003.exr") + " --png " + path("out/o.0003.png");
  const std::vector<std::string> two_frames{"o.0001.exr", "o.0001.png", "o.0002.exr", "o.0002.png"};
  std::vector<std::string> three_frames = two_frames;
  three_frames.insert(three_frames.end(), {"o.0003.exr", "o.0003.png"});
  // One signal in a sequence: the write in progress completes (the held rename goes on once the
  // handler has returned), the run exits 128 + N. A second signal, or one in a single-file run: the
  // process ends by that signal at once, frame 3 unwritten. Either way no temporary is left.
  const struct {
    const char* what;
    std::string args;
    std::vector<int> signals;
    int release;  // handled signals after which the held rename goes on (0: never)
    std::string ends;
    std::vector<std::string> files;  // out/ afterwards
    std::string says;                // in the log
  } cases[] = {
      {"sequence, SIGTERM", sequence, {SIGTERM}, 1, "exit 143", three_frames, "interrupted: 3 of 8 frames written"},
      {"sequence, SIGINT", sequence, {SIGINT}, 1, "exit 130", three_frames, "interrupted: 3 of 8 frames written"},
      {"sequence, double Ctrl-C", sequence, {SIGINT, SIGINT}, 0, "signal 2", two_frames, ""},
      {"sequence, SIGINT then SIGTERM", sequence, {SIGINT, SIGTERM}, 0, "signal 15", two_frames, ""},
      {"single file, SIGTERM", single, {SIGTERM}, 0, "signal 15", {}, ""},
      {"single file, SIGINT", single, {SIGINT}, 0, "signal 2", {}, ""},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    for (const auto& e : fs::directory_iterator(path("out"))) fs::remove(e.path());
    GatedCli run(c.args, path("log.txt"), true, kNamingCalls, "/out/o.0003.exr", c.release);
    const std::string held = run.next_line();
    ASSERT_EQ(held, "held rename " + path("out/o.0003.exr")) << read_text(path("log.txt"));
    // Both files of frame 3 are written under their temporaries; only the naming is left.
    const std::vector<std::string> writing = temporaries_in(path("out"));
    EXPECT_EQ(writing.size(), 2u);
    for (int signo : c.signals) {
      run.signal(signo);
      EXPECT_EQ(run.next_line(), "handled " + std::to_string(signo));
    }
    const std::string ends = ending(run.wait());
    const std::string log = read_text(path("log.txt"));
    const std::vector<std::string> left = temporaries_in(path("out"));
    std::printf("[ signal   ] %s: %s, %zu temporary file(s) while held, %zu left\n", c.what, ends.c_str(),
                writing.size(), left.size());
    EXPECT_EQ(ends, c.ends) << log;
    EXPECT_EQ(files_in(path("out")), c.files) << log;
    if (!c.says.empty()) {
      EXPECT_NE(log.find(c.says), std::string::npos) << log;
    }
    for (const std::string& f : c.files) {
      if (f.size() > 4 && f.compare(f.size() - 4, 4, ".exr") == 0) {
        EXPECT_NO_THROW(read_exr_color(path("out/" + f))) << f << " is not a complete frame";
      }
    }
  }
}

// ---- Messages and exit codes -----------------------------------------------------------------------

TEST_F(CliSafety, EachMisuseSaysWhatInOneLineWithItsExitCode) {
  fs::create_directories(path("a-folder"));
  write_text(path("nul-key.json"), std::string(R"({"volumes": [{"center": [0, 1, 4], "radius": 2, "ra\u0000dius": 1}]})"));
  write_text(path("nul-top.json"), std::string(R"({"vol\u0000umes": []})"));
  const std::string out = " --out " + path("o.exr");
  const struct {
    std::string args, says;
    int code;
  } cases[] = {
      // Rules: exit 1.
      {apply_no_fov("--fov 0" + out), "--fov must be in (0, 180) degrees (got 0)", 1},
      {apply_no_fov("--fov -5" + out), "--fov must be in (0, 180) degrees (got -5)", 1},
      {apply("--aspect 0" + out), "--aspect must be finite and > 0 (got 0)", 1},
      {apply("--aspect -2" + out), "--aspect must be finite and > 0 (got -2)", 1},
      {apply("--threads 99999999999999999999" + out), "--threads must be between 1 and 4096 (got 99999999999999999999)",
       1},
      {apply(volume_flags() + " --steps 99999999999999999999" + out),
       "--steps must be in [1, 4096] (got 99999999999999999999)", 1},
      {apply(volume_flags() + " --noise-seed 99999999999999999999" + out),
       "--noise-seed must be in [0, 4294967295] (got 99999999999999999999)", 1},
      {apply(volume_flags() + " --frame -99999999999999999999" + out),
       "--frame must be in [0, 4294967295] (got -99999999999999999999)", 1},
      {"demo --width 0 --out " + path("demo"), "--width must be in [1, 16384] (got 0)", 1},
      {"report --volumetric --steps 8,99999999999999999999 --out " + path("report"),
       "--steps must be in [1, 4096] (got 99999999999999999999 in '8,99999999999999999999')", 1},
      {apply("--mode fog" + out), "--mode must be one of off, linear, exp, exp2 or height (got 'fog')", 1},
      {"apply --color " + path("a-folder") + " --near 0.3 --far 1000 --fov 60 --mode exp" + out,
       "--color '" + path("a-folder") + "': is a directory, not a file", 1},
      {"apply --color " + path("color.exr") + " --depth " + path("a-folder") + kFog + out,
       "--depth '" + path("a-folder") + "': is a directory, not a file", 1},
      {"apply --color " + path("color.exr") + " --depth " + path("depth.exr") + kFog + " --volumes " + path("a-folder") +
           " --eye 0,1.6,-6 --forward 0,0,1 --up 0,1,0" + out,
       "--volumes '" + path("a-folder") + "': is a directory, not a file", 1},
      {apply("--out " + path("no-folder/o.exr")), "the folder '" + path("no-folder") + "' does not exist", 1},
      {"apply --color " + path("color.exr") + " --depth " + path("depth.exr") + kFog + " --volumes " +
           path("nul-key.json") + " --eye 0,1.6,-6 --forward 0,0,1 --up 0,1,0" + out,
       "volume 0: unknown key 'ra\\u0000dius' (", 1},
      {"apply --color " + path("color.exr") + " --depth " + path("depth.exr") + kFog + " --volumes " +
           path("nul-top.json") + " --eye 0,1.6,-6 --forward 0,0,1 --up 0,1,0" + out,
       "top level: unknown key 'vol\\u0000umes' (the keys are \"volumes\" and \"lights\")", 1},
      // Usage errors: exit 2.
      {apply("--bogus" + out), "fogcl: error: unknown option '--bogus' for fogcl apply (see --help)", 2},
      {apply_no_fov(out + " --fov"), "--fov", 2},
      {apply_no_fov("--fov abc" + out), "--fov must be a number (got 'abc')", 2},
      {apply("--threads 2x" + out), "--threads must be an integer, between 1 and 4096 (got '2x')", 2},
      {apply(out + " --out " + path("p.exr")), "--out", 2},
      {apply(""), "--out is required", 2},
      {"apply --color " + path("color.exr") + " --near 0.3 --fov 60 --mode exp" + out,
       "--far is required (except with --infinite-far)", 2},
      {"apply --color " + path("color.exr") + " --near 0.3 --far 100 --fov 60" + out, "--mode is required", 2},
      {"", "a command is required", 2},
      {"paint", "paint", 2},
  };
  for (const auto& c : cases) {
    const CliRun r = run_cli(c.args);
    std::printf("[ exit %d   ] %s", r.exit_code, r.output.c_str());
    EXPECT_EQ(r.exit_code, c.code) << c.args << "\n" << r.output;
    EXPECT_EQ(lines(r.output), 1) << c.args << "\n" << r.output;
    EXPECT_EQ(r.output.rfind("fogcl: error: ", 0), 0u) << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.args << "\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(path("o.exr")));
}

TEST_F(CliSafety, HelpListsTheExitCodesOfEveryCommand) {
  for (const char* command : {"", "demo ", "apply ", "report "}) {
    const CliRun r = run_cli(std::string(command) + "--help");
    EXPECT_EQ(r.exit_code, 0) << command;
    for (const char* says : {"Exit codes: 0 done; 1 error", "2 usage error", "128+N stopped by signal N"})
      EXPECT_NE(r.output.find(says), std::string::npos) << command << "--help lacks '" << says << "'";
  }
}

// PoCL keeps compiled kernels under HOME (or XDG_CACHE_HOME, or POCL_CACHE_DIR): a folder it cannot
// create or write is named in one line, not "no OpenCL device matches" or a bare build failure.
TEST_F(CliSafety, AnUnusablePoclCacheIsNamed) {
  FOGCL_REQUIRE_DEVICE();
  if (cli_device() != "cpu") GTEST_SKIP() << "PoCL's CPU device only (FOGCL_DEVICE=" << cli_device() << ")";
  write_text(path("a-file"), "not a folder");
  const std::string args = "apply --color " + path("color.exr") + " --depth " + path("depth.exr") +
                           " --near 0.3 --far 1000 --fov 60 --mode exp --device cpu --out " + path("o.exr");
  const struct {
    std::string env, says;
  } cases[] = {
      {"env -u XDG_CACHE_HOME -u POCL_CACHE_DIR HOME=/proc/no-home",
       "PoCL (the OpenCL CPU driver) cannot use its kernel cache folder '/proc/no-home/.cache/pocl/kcache' (from HOME)"},
      {"env -u XDG_CACHE_HOME POCL_CACHE_DIR=" + path("a-file"),
       "its kernel cache folder '" + path("a-file") + "' (from POCL_CACHE_DIR): it is not a folder"},
      {"env -u XDG_CACHE_HOME POCL_CACHE_DIR=/proc", "its kernel cache folder '/proc' (from POCL_CACHE_DIR): it cannot be written"},
  };
  for (const auto& c : cases) {
    const CliRun r = run_cli(args, c.env);
    std::printf("[ exit %d   ] %s", r.exit_code, r.output.c_str());
    EXPECT_EQ(r.exit_code, 1) << c.env << "\n" << r.output;
    EXPECT_EQ(lines(r.output), 1) << c.env << "\n" << r.output;
    EXPECT_NE(r.output.find(c.says), std::string::npos) << c.env << "\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(path("o.exr")));
}

}  // namespace
}  // namespace fogcl::test
