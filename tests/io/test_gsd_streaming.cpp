// Streaming GSD writes (issue 13): frames made row by row and written through buffers of any
// size give exactly the bytes of the one-shot writer; and every write path reports a failing
// write (ENOSPC, EFBIG) naming the file and the OS error, keeping the previous file.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fmt/format.h>

#include "io/files.hpp"
#include "io/gsd_hoomd.hpp"
#include "io/gsd_sample_frame.hpp"
#include "io/gsd_test_util.hpp"

namespace hb::gsd {
namespace {

using test::expect_error;
using test::file_bytes;
using test::TempDir;

// The same values, but made row by row on demand instead of handed over in memory.
ChunkSource as_rows(const ChunkSource& m) {
  if (!m.data) return m;
  ChunkSource s = m;
  s.data = nullptr;
  s.fill = [m](std::uint64_t first, std::uint64_t count, std::byte* out) {
    std::memcpy(out, static_cast<const std::byte*>(m.data) + first * m.row_bytes(),
                count * m.row_bytes());
  };
  return s;
}
FrameSource generated(const HoomdFrame& f) {
  FrameSource s = frame_source(f);
  for (ChunkSource* c : {&s.position, &s.orientation, &s.type_id, &s.diameter, &s.velocity,
                         &s.angmom, &s.image})
    *c = as_rows(*c);
  for (auto& [key, c] : s.log) c = as_rows(c);
  return s;
}

// Frames that exercise the omission rules: frame 1 repeats frame 0's orientations and type ids
// (left out), frame 2 has identity orientations and another N (default, not frame 0's).
std::vector<HoomdFrame> trajectory() {
  std::vector<HoomdFrame> t{test::sample_frame(0, 300, 1), test::sample_frame(5, 300, 2),
                            test::sample_frame(9, 120, 3)};
  t[1].orientation = t[0].orientation;
  t[1].type_id = t[0].type_id;
  t[1].types.clear();
  test::set_identity_orientations(t[2]);
  return t;
}

void write_all_frames(const std::filesystem::path& p, std::size_t buffer, bool rows) {
  auto w = HoomdWriter::create(p);
  if (buffer > 0) w.set_buffer_size(buffer);
  const auto frames = trajectory();
  for (const auto& f : frames) {
    if (rows) w.write_frame(generated(f));
    else w.write_frame(f);
  }
  w.close();
}

TEST(GsdStreaming, AnyBufferSizeAndRowSourcesGiveTheOneShotBytes) {
  TempDir dir;
  write_all_frames(dir / "ref.gsd", 0, false);
  const auto want = file_bytes(dir / "ref.gsd");
  {  // the omission rules were exercised
    const Reader r(dir / "ref.gsd");
    ASSERT_EQ(r.nframes(), 3u);
    EXPECT_FALSE(r.has(1, "particles/orientation"));
    EXPECT_FALSE(r.has(1, "particles/typeid"));
    EXPECT_FALSE(r.has(2, "particles/orientation"));
    EXPECT_TRUE(r.has(2, "particles/typeid"));
  }
  for (std::size_t buffer : {1, 7, 100, 4096}) {
    for (bool rows : {false, true}) {
      const auto p = dir / fmt::format("b{}_{}.gsd", buffer, rows);
      write_all_frames(p, buffer, rows);
      EXPECT_EQ(file_bytes(p), want) << "buffer " << buffer << (rows ? " row sources" : " memory");
    }
  }
}

TEST(GsdStreaming, AppendingThroughATinyBufferGivesTheSameFile) {
  TempDir dir;
  write_all_frames(dir / "ref.gsd", 0, false);
  const auto frames = trajectory();
  {
    auto w = HoomdWriter::create(dir / "a.gsd");
    w.write_frame(frames[0]);
    w.close();
  }
  {
    auto w = HoomdWriter::append(dir / "a.gsd");
    w.set_buffer_size(3);  // frame 0's chunks are compared by reading them back in pieces
    w.write_frame(generated(frames[1]));
    w.write_frame(generated(frames[2]));
    w.close();
  }
  EXPECT_EQ(file_bytes(dir / "a.gsd"), file_bytes(dir / "ref.gsd"));
}

TEST(GsdStreaming, AtomicFrameFromSourcesEqualsTheInMemoryOne) {
  TempDir dir;
  const HoomdFrame f = test::sample_frame(42, 500, 7);
  write_frame_atomic(dir / "a.gsd", f);
  write_frame_atomic(dir / "b.gsd", generated(f), 13);
  EXPECT_EQ(file_bytes(dir / "a.gsd"), file_bytes(dir / "b.gsd"));
  EXPECT_FALSE(std::filesystem::exists(dir / "b.gsd.tmp"));
}

TEST(GsdStreaming, IntegerLogChunksReadBackAsExactDoubles) {
  TempDir dir;
  HoomdFrame f = test::sample_frame(1, 4, 1);
  FrameSource s = frame_source(f);
  const std::vector<std::uint32_t> counts{0, 1, 4000000000u, 7};
  const std::vector<std::int32_t> images{-3, 0, 2, 2147483647, -2147483647 - 1, 5};
  s.log["particles/hardbody/count"] = memory_source(counts, 1);
  s.log["hardbody/images"] = memory_source(images, 3);
  write_frame_atomic(dir / "c.gsd", s);
  const HoomdFrame g = read_last_frame(dir / "c.gsd");
  EXPECT_EQ(g.log.at("particles/hardbody/count").values,
            (std::vector<double>{0, 1, 4000000000.0, 7}));
  EXPECT_EQ(g.log.at("hardbody/images").rows, 2u);
  EXPECT_EQ(g.log.at("hardbody/images").values,
            (std::vector<double>{-3, 0, 2, 2147483647.0, -2147483648.0, 5}));
  const Reader r(dir / "c.gsd");
  EXPECT_EQ(r.find(0, "log/particles/hardbody/count")->type, Type::uint32);
}

TEST(GsdStreaming, AFrameSourceOfTheWrongShapeIsRefusedBeforeWriting) {
  TempDir dir;
  const HoomdFrame f = test::sample_frame(1, 10, 1);
  FrameSource s = frame_source(f);
  const std::vector<float> short_velocity(3 * 9, 0.0f);
  s.velocity = memory_source(short_velocity, 3);
  expect_error<std::invalid_argument>([&] { write_frame_atomic(dir / "s.gsd", s); },
                                      {"velocity", "9 x 3"});
  EXPECT_FALSE(std::filesystem::exists(dir / "s.gsd"));
  EXPECT_FALSE(std::filesystem::exists(dir / "s.gsd.tmp"));
}

// ---------------------------------------------------------------------------------------------
// Write errors. /dev/full fails every write with ENOSPC; a temporary name that is a symbolic
// link to it makes an atomic write meet a full disk.

bool have_dev_full() { return std::filesystem::exists("/dev/full"); }

TEST(WriteErrors, GsdWriterOnAFullDeviceNamesTheFileAndTheError) {
  if (!have_dev_full()) GTEST_SKIP() << "no /dev/full";
  expect_error<std::runtime_error>(
      [] { Writer::create("/dev/full", "hardbody", "hoomd", kHoomdSchemaVersion); },
      {"/dev/full", "No space left on device"});
}

TEST(WriteErrors, AppendedRowsOnAFullDeviceThrow) {
  if (!have_dev_full()) GTEST_SKIP() << "no /dev/full";
  AppendFile f("/dev/full");
  expect_error<std::runtime_error>([&] { f.write("1\t2\t3\n"); },
                                   {"/dev/full", "No space left on device"});
}

TEST(WriteErrors, AtomicWritesOnAFullDiskKeepThePreviousFileAndRemoveTheTemporary) {
  if (!have_dev_full()) GTEST_SKIP() << "no /dev/full";
  TempDir dir;
  const auto ck = dir / "checkpoint.gsd";
  write_frame_atomic(ck, test::sample_frame(1, 50, 1));
  const auto before = file_bytes(ck);
  std::filesystem::create_symlink("/dev/full", dir / "checkpoint.gsd.tmp");
  expect_error<std::runtime_error>(
      [&] { write_frame_atomic(ck, generated(test::sample_frame(2, 50, 2)), 64); },
      {"checkpoint.gsd.tmp", "No space left on device", "previous checkpoint.gsd is unchanged"});
  EXPECT_EQ(file_bytes(ck), before);
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(dir / "checkpoint.gsd.tmp")));

  const std::string summary = (dir / "summary.json").string();
  write_file_atomic(summary, "{\"old\": 1}\n");
  std::filesystem::create_symlink("/dev/full", summary + ".tmp");
  expect_error<std::runtime_error>([&] { write_file_atomic(summary, std::string(100000, 'x')); },
                                   {"summary.json.tmp", "No space left on device"});
  EXPECT_EQ(file_bytes(summary), std::vector<char>({'{', '"', 'o', 'l', 'd', '"', ':', ' ', '1', '}', '\n'}));
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::symlink_status(summary + ".tmp")));
}

// A file size limit (RLIMIT_FSIZE) makes writes past it fail part way (a short write, then
// EFBIG): the failure is reported, and a trajectory keeps the frames it had.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    ::getrlimit(RLIMIT_FSIZE, &old_);
    rlimit lim = old_;
    lim.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &lim);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit old_{};
  void (*old_handler_)(int) = nullptr;
};

TEST(WriteErrors, AShortWriteIsReportedAndEarlierFramesStayReadable) {
  TempDir dir;
  const auto traj = dir / "trajectory.gsd";
  auto w = HoomdWriter::create(traj);
  w.write_frame(test::sample_frame(0, 100, 1));
  w.sync();
  const auto size = std::filesystem::file_size(traj);
  {
    FileSizeLimit limit(size + 1000);  // the next frame (~10 kB) does not fit
    expect_error<std::runtime_error>([&] { w.write_frame(generated(test::sample_frame(1, 100, 2))); },
                                     {"trajectory.gsd", std::strerror(EFBIG)});
    expect_error<std::runtime_error>(
        [&] { write_file_atomic((dir / "gr.tsv").string(), std::string(size + 2000, 'y')); },
        {"gr.tsv.tmp", std::strerror(EFBIG)});
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "gr.tsv.tmp"));
  const Reader r(traj);
  EXPECT_EQ(r.nframes(), 1u);
}

}  // namespace
}  // namespace hb::gsd
