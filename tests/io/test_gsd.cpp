// GSD file layer: round trips of every type, append, block growth, crash safety, and clear
// errors for corrupt or truncated files.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>
#include <limits>
#include <numeric>

#include "io/gsd.hpp"
#include "io/gsd_test_util.hpp"

namespace hb::gsd {
namespace {

using test::expect_error;
using test::patch;
using test::TempDir;

constexpr std::uint64_t kIndexAt = 256;  // where a fresh file keeps its index block

template <class T>
std::vector<T> ramp(std::size_t n, double scale) {
  std::vector<T> v(n);
  const double offset = std::is_signed_v<T> ? -3.0 : 3.0;  // no negative -> unsigned casts
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<T>(scale * static_cast<double>(i) + offset);
  return v;
}

template <class T>
void expect_chunk(const Reader& r, std::uint64_t frame, const std::string& name, std::uint64_t N,
                  std::uint32_t M, const std::vector<T>& want) {
  const Array<T> a = r.read<T>(frame, name);
  EXPECT_EQ(a.N, N) << name;
  EXPECT_EQ(a.M, M) << name;
  ASSERT_EQ(a.data.size(), want.size()) << name;
  EXPECT_EQ(std::memcmp(a.data.data(), want.data(), want.size() * sizeof(T)), 0) << name;
}

// A small file: frame f holds "a" (float64 2x3) and "b" (uint32 4x1) with values from f.
void write_small(const std::filesystem::path& p, int frames) {
  Writer w = Writer::create(p, "hardbody", "test", {1, 2});
  for (int f = 0; f < frames; ++f) {
    w.write_chunk<double>("a", 2, 3, ramp<double>(6, 0.1 + f));
    w.write_chunk<std::uint32_t>("b", 4, 1, ramp<std::uint32_t>(4, 1 + f));
    w.end_frame();
  }
}

TEST(GsdFile, EveryTypeRoundTripsBitExact) {
  TempDir dir;
  const auto p = dir / "types.gsd";
  std::vector<double> doubles = ramp<double>(6, 0.1);
  doubles[1] = -0.0;
  doubles[2] = std::numeric_limits<double>::denorm_min();
  doubles[3] = std::numeric_limits<double>::quiet_NaN();
  doubles[4] = 1.0 + std::numeric_limits<double>::epsilon();
  {
    Writer w = Writer::create(p, "hardbody", "test", {1, 4});
    for (int frame = 0; frame < 2; ++frame) {
      w.write_chunk<std::uint8_t>("u8", 3, 1, ramp<std::uint8_t>(3, 7));
      w.write_chunk<std::uint16_t>("u16", 1, 3, ramp<std::uint16_t>(3, 700));
      w.write_chunk<std::uint32_t>("u32", 2, 2, ramp<std::uint32_t>(4, 70000));
      w.write_chunk<std::uint64_t>("u64", 1, 1, std::vector<std::uint64_t>{~0ull - frame});
      w.write_chunk<std::int8_t>("i8", 2, 1, ramp<std::int8_t>(2, -5));
      w.write_chunk<std::int16_t>("i16", 2, 1, ramp<std::int16_t>(2, -500));
      w.write_chunk<std::int32_t>("i32", 3, 3, ramp<std::int32_t>(9, -50000));
      w.write_chunk<std::int64_t>("i64", 1, 2, ramp<std::int64_t>(2, -5e12));
      w.write_chunk<float>("f32", 2, 3, ramp<float>(6, 0.3));
      w.write_chunk<double>("f64", 3, 2, doubles);
      w.end_frame();
    }
    EXPECT_EQ(w.frame(), 2u);
  }
  const Reader r(p);
  EXPECT_EQ(r.nframes(), 2u);
  EXPECT_EQ(r.application(), "hardbody");
  EXPECT_EQ(r.schema(), "test");
  EXPECT_EQ(r.schema_version(), (Version{1, 4}));
  EXPECT_EQ(r.file_version(), (Version{2, 0}));
  EXPECT_EQ(r.names().size(), 10u);
  for (std::uint64_t f = 0; f < 2; ++f) {
    expect_chunk(r, f, "u8", 3, 1, ramp<std::uint8_t>(3, 7));
    expect_chunk(r, f, "u16", 1, 3, ramp<std::uint16_t>(3, 700));
    expect_chunk(r, f, "u32", 2, 2, ramp<std::uint32_t>(4, 70000));
    expect_chunk(r, f, "u64", 1, 1, std::vector<std::uint64_t>{~0ull - f});
    expect_chunk(r, f, "i8", 2, 1, ramp<std::int8_t>(2, -5));
    expect_chunk(r, f, "i16", 2, 1, ramp<std::int16_t>(2, -500));
    expect_chunk(r, f, "i32", 3, 3, ramp<std::int32_t>(9, -50000));
    expect_chunk(r, f, "i64", 1, 2, ramp<std::int64_t>(2, -5e12));
    expect_chunk(r, f, "f32", 2, 3, ramp<float>(6, 0.3));
    expect_chunk(r, f, "f64", 3, 2, doubles);
    EXPECT_EQ(r.find(f, "f64")->type, Type::float64);
  }
  EXPECT_EQ(r.names_with_prefix("u").size(), 4u);
}

TEST(GsdFile, MissingChunkWrongTypeAndWrongShapeAreNamed) {
  TempDir dir;
  const auto p = dir / "small.gsd";
  write_small(p, 2);
  const Reader r(p);
  EXPECT_EQ(r.find(0, "zzz"), nullptr);
  EXPECT_EQ(r.find(5, "a"), nullptr);
  EXPECT_TRUE(r.has(1, "b"));
  expect_error<std::runtime_error>([&] { (void)r.read<double>(0, "zzz"); },
                                   {p.string(), "frame 0 has no chunk 'zzz'"});
  expect_error<std::runtime_error>([&] { (void)r.read<float>(1, "a"); },
                                   {p.string(), "'a'", "frame 1", "float64", "expected float32"});
  expect_error<std::runtime_error>([&] { (void)r.read<double>(0, "a", 3, 2); },
                                   {p.string(), "'a'", "2 x 3", "expected 3 x 2"});
  EXPECT_EQ(r.read<double>(0, "a", 2, 3), ramp<double>(6, 0.1));
}

TEST(GsdFile, EmptyChunkAndEmptyFile) {
  TempDir dir;
  const auto p = dir / "empty.gsd";
  { Writer w = Writer::create(p, "hardbody", "test", {1, 0}); }
  EXPECT_EQ(Reader(p).nframes(), 0u);
  {
    Writer w = Writer::append(p);
    w.write_chunk<float>("none", 0, 3, std::vector<float>{});
    w.end_frame();
  }
  const Reader r(p);
  ASSERT_EQ(r.nframes(), 1u);
  const Array<float> a = r.read<float>(0, "none");
  EXPECT_EQ(a.N, 0u);
  EXPECT_EQ(a.M, 3u);
  EXPECT_TRUE(a.data.empty());
}

TEST(GsdFile, IndexAndNamelistGrowBeyondTheirFirstBlocks) {
  TempDir dir;
  const auto p = dir / "big.gsd";
  constexpr int kFrames = 300;  // 2 entries per frame: far more than the first 128-entry block
  constexpr int kNames = 100;   // ~30 bytes each: more than the first 1 KiB namelist
  auto long_name = [](int i) { return "log/some/rather/long/name/" + std::to_string(i); };
  {
    Writer w = Writer::create(p, "hardbody", "test", {1, 0});
    for (int f = 0; f < kFrames; ++f) {
      w.write_chunk<std::uint64_t>("value", 1, 2, std::vector<std::uint64_t>{std::uint64_t(f), 7});
      w.write_chunk<std::int32_t>(long_name(f % kNames), 1, 1, std::vector<std::int32_t>{-f});
      w.end_frame();
    }
  }
  const Reader r(p);
  ASSERT_EQ(r.nframes(), std::uint64_t{kFrames});
  EXPECT_EQ(r.names().size(), std::size_t{kNames + 1});
  for (int f = 0; f < kFrames; ++f) {
    EXPECT_EQ(r.read<std::uint64_t>(f, "value", 1, 2), (std::vector<std::uint64_t>{std::uint64_t(f), 7}));
    EXPECT_EQ(r.read<std::int32_t>(f, long_name(f % kNames), 1, 1)[0], -f);
    EXPECT_FALSE(r.has(f, long_name((f + 1) % kNames)));
  }
}

TEST(GsdFile, AppendContinuesAfterTheLastFrame) {
  TempDir dir;
  const auto p = dir / "append.gsd";
  write_small(p, 2);
  {
    Writer w = Writer::append(p, "test");
    EXPECT_EQ(w.frame(), 2u);
    w.write_chunk<double>("a", 2, 3, ramp<double>(6, 2.1));
    w.write_chunk<std::int64_t>("new", 1, 1, std::vector<std::int64_t>{-9});
    w.end_frame();
  }
  const Reader r(p);
  ASSERT_EQ(r.nframes(), 3u);
  EXPECT_EQ(r.schema_version(), (Version{1, 2}));
  EXPECT_EQ(r.read<double>(1, "a", 2, 3), ramp<double>(6, 1.1));
  EXPECT_EQ(r.read<std::uint32_t>(1, "b", 4, 1), ramp<std::uint32_t>(4, 2));
  EXPECT_EQ(r.read<double>(2, "a", 2, 3), ramp<double>(6, 2.1));
  EXPECT_EQ(r.read<std::int64_t>(2, "new", 1, 1)[0], -9);
  EXPECT_FALSE(r.has(2, "b"));
  expect_error<std::runtime_error>([&] { (void)Writer::append(p, "hoomd"); },
                                   {p.string(), "schema is 'test', expected 'hoomd'"});
}

TEST(GsdFile, UnfinishedFrameIsDroppedAndTheFileStaysAppendable) {
  TempDir dir;
  const auto p = dir / "unfinished.gsd";
  write_small(p, 2);
  {
    Writer w = Writer::append(p);
    w.write_chunk<double>("a", 2, 3, ramp<double>(6, 5.0));
    w.write_chunk<std::uint8_t>("only_in_dropped_frame", 1, 1, std::vector<std::uint8_t>{1});
  }  // no end_frame()
  EXPECT_EQ(Reader(p).nframes(), 2u);
  {
    Writer w = Writer::append(p);
    EXPECT_EQ(w.frame(), 2u);
    w.write_chunk<double>("a", 2, 3, ramp<double>(6, 6.0));
    w.end_frame();
  }
  const Reader r(p);
  ASSERT_EQ(r.nframes(), 3u);
  EXPECT_EQ(r.read<double>(2, "a", 2, 3), ramp<double>(6, 6.0));
  EXPECT_EQ(r.read<double>(0, "a", 2, 3), ramp<double>(6, 0.1));
}

TEST(GsdFile, ProcessKilledMidFrameLeavesTheCompletedFrames) {
  TempDir dir;
  const auto p = dir / "killed.gsd";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    try {
      Writer w = Writer::create(p, "hardbody", "test", {1, 0});
      for (int f = 0; f < 3; ++f) {
        w.write_chunk<double>("a", 2, 3, ramp<double>(6, f));
        w.end_frame();
      }
      // A chunk big enough to go to the file at once, then death before end_frame().
      w.write_chunk<double>("a", 1 << 20, 2, std::vector<double>(std::size_t{2} << 20, 1.5));
      ::kill(::getpid(), SIGKILL);
    } catch (...) {
    }
    ::_exit(1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "child status " << status;
  EXPECT_GT(std::filesystem::file_size(p), std::uint64_t{16} << 20);  // the orphan data is there
  {
    const Reader r(p);
    ASSERT_EQ(r.nframes(), 3u);
    for (int f = 0; f < 3; ++f) EXPECT_EQ(r.read<double>(f, "a", 2, 3), ramp<double>(6, f));
  }
  {
    Writer w = Writer::append(p);
    w.write_chunk<double>("a", 2, 3, ramp<double>(6, 3));
    w.end_frame();
  }
  const Reader r(p);
  ASSERT_EQ(r.nframes(), 4u);
  EXPECT_EQ(r.read<double>(3, "a", 2, 3), ramp<double>(6, 3));
}

TEST(GsdFile, WriterRejectsBadChunks) {
  TempDir dir;
  const auto p = dir / "bad.gsd";
  Writer w = Writer::create(p, "hardbody", "test", {1, 0});
  const std::vector<float> v(6, 1.0f);
  expect_error<std::invalid_argument>([&] { w.write_chunk<float>("x", 3, 0, std::vector<float>{}); },
                                      {p.string(), "'x'", "M must be at least 1"});
  expect_error<std::invalid_argument>([&] { w.write_chunk<float>("x", 2, 2, v); },
                                      {p.string(), "'x'", "2 x 2", "6 values"});
  expect_error<std::invalid_argument>([&] { w.write_chunk<float>("", 2, 3, v); }, {"empty name"});
  expect_error<std::invalid_argument>(
      [&] { w.write_chunk("c", Type::character, 1, 1, "x"); }, {"character"});
  w.write_chunk<float>("x", 2, 3, v);
  expect_error<std::invalid_argument>([&] { w.write_chunk<float>("x", 2, 3, v); },
                                      {"'x'", "already written in frame 0"});
  w.end_frame();
  w.write_chunk<float>("x", 2, 3, v);  // a new frame may use the name again
  w.end_frame();
  w.close();
  expect_error<std::logic_error>([&] { w.end_frame(); }, {"closed"});
  EXPECT_EQ(Reader(p).nframes(), 2u);
}

// ---------------------------------------------------------------------------------------------
// Corrupt and truncated files: every error names the file and the problem.

class GsdCorrupt : public ::testing::Test {
 protected:
  void SetUp() override { write_small(path, 3); }
  void expect_open_error(std::initializer_list<std::string> fragments) {
    std::vector<std::string> all{path.string()};
    all.insert(all.end(), fragments.begin(), fragments.end());
    try {
      Reader r(path);
      ADD_FAILURE() << "file opened without error";
    } catch (const std::runtime_error& e) {
      const std::string msg = e.what();
      for (const auto& frag : all)
        EXPECT_NE(msg.find(frag), std::string::npos) << "message: " << msg << "\nmissing: " << frag;
    }
  }
  TempDir dir;
  std::filesystem::path path = dir / "corrupt.gsd";
};

TEST_F(GsdCorrupt, MissingFile) {
  path = dir / "does-not-exist.gsd";
  expect_open_error({"cannot open", "No such file"});
}

TEST_F(GsdCorrupt, EmptyOrShortFile) {
  std::filesystem::resize_file(path, 0);
  expect_open_error({"truncated header", "0 bytes"});
  std::filesystem::resize_file(path, 100);
  expect_open_error({"truncated header", "100 bytes"});
}

TEST_F(GsdCorrupt, BadMagic) {
  patch<std::uint8_t>(path, 3, 0x42);
  expect_open_error({"bad magic number", "not a GSD file"});
}

TEST_F(GsdCorrupt, TextFileIsNotGsd) {
  std::ofstream(path) << "# this is a TOML file, not a trajectory\n" << std::string(300, 'x');
  expect_open_error({"bad magic number"});
}

TEST_F(GsdCorrupt, UnknownVersion) {
  patch<std::uint32_t>(path, 44, 3u << 16);
  expect_open_error({"unknown GSD file layer version 3.0"});
}

TEST_F(GsdCorrupt, IndexPastTheEnd) {
  patch<std::uint64_t>(path, 16, 1u << 30);  // index_allocated_entries
  expect_open_error({"truncated index"});
  patch<std::uint64_t>(path, 16, ~0ull);  // overflows when multiplied by 32
  expect_open_error({"truncated index"});
}

TEST_F(GsdCorrupt, NamelistPastTheEnd) {
  patch<std::uint64_t>(path, 32, 1u << 20);  // namelist_allocated_entries
  expect_open_error({"truncated namelist"});
}

TEST_F(GsdCorrupt, TruncatedData) {
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size - 5);  // cuts into the last chunk
  expect_open_error({"chunk 'b' of frame 2", "out of bounds", "truncated"});
}

TEST_F(GsdCorrupt, ChunkLocationPastTheEnd) {
  patch<std::int64_t>(path, kIndexAt + 16, 1ll << 40);  // entry 0 location
  expect_open_error({"chunk 'a' of frame 0", "out of bounds"});
}

TEST_F(GsdCorrupt, HugeChunkSizeDoesNotOverflow) {
  patch<std::uint64_t>(path, kIndexAt + 8, 1ull << 62);  // entry 0 N; N * M * 8 wraps
  expect_open_error({"out of bounds"});
}

TEST_F(GsdCorrupt, UnknownTypeId) {
  patch<std::uint8_t>(path, kIndexAt + 30, 99);
  expect_open_error({"index entry 0", "unknown type id 99"});
}

TEST_F(GsdCorrupt, NameIdOutsideTheNamelist) {
  patch<std::uint16_t>(path, kIndexAt + 32 + 28, 500);  // entry 1
  expect_open_error({"index entry 1", "name id 500"});
}

TEST_F(GsdCorrupt, FramesOutOfOrder) {
  patch<std::uint64_t>(path, kIndexAt + 0, 2);  // entry 0 claims frame 2, entry 1 is frame 0
  expect_open_error({"index entry 1", "not sorted"});
}

TEST_F(GsdCorrupt, ZeroColumns) {
  patch<std::uint32_t>(path, kIndexAt + 24, 0);
  expect_open_error({"index entry 0", "M = 0"});
}

TEST_F(GsdCorrupt, AppendRefusesACorruptFile) {
  patch<std::uint8_t>(path, 0, 0);
  expect_error<std::runtime_error>([&] { (void)Writer::append(path); },
                                   {path.string(), "bad magic number"});
}

}  // namespace
}  // namespace hb::gsd
