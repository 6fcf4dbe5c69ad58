// HOOMD-schema frames: every field back bit for bit, the frame-0/default omission rule, append,
// validation before writing, atomic checkpoints.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>

#include "io/gsd_hoomd.hpp"
#include "io/gsd_sample_frame.hpp"
#include "io/gsd_test_util.hpp"

namespace hb::gsd {
namespace {

using test::expect_error;
using test::file_bytes;
using test::TempDir;

HoomdFrame make_frame(std::uint64_t step, std::uint32_t N, int seed) {
  return test::sample_frame(step, N, seed);
}

void expect_same_bits(const std::vector<double>& a, const std::vector<double>& b,
                      const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)), 0) << what;
}

void expect_frames_equal(const HoomdFrame& got, const HoomdFrame& want) {
  EXPECT_EQ(got.step, want.step);
  EXPECT_EQ(got.dimensions, want.dimensions);
  EXPECT_EQ(got.box, want.box);
  EXPECT_EQ(got.N, want.N);
  EXPECT_EQ(got.position, want.position);
  EXPECT_EQ(got.orientation, want.orientation);
  EXPECT_EQ(got.type_id, want.type_id);
  EXPECT_EQ(got.types, want.types);
  EXPECT_EQ(got.type_shapes, want.type_shapes);
  EXPECT_EQ(got.velocity, want.velocity);
  EXPECT_EQ(got.angmom, want.angmom);
  EXPECT_EQ(got.image, want.image);
  ASSERT_EQ(got.log.size(), want.log.size());
  for (const auto& [key, a] : want.log) {
    ASSERT_TRUE(got.log.count(key)) << key;
    const LogArray& b = got.log.at(key);
    EXPECT_EQ(b.rows, a.rows) << key;
    EXPECT_EQ(b.cols, a.cols) << key;
    expect_same_bits(b.values, a.values, key);
  }
}

TEST(GsdHoomd, EveryFieldRoundTrips) {
  TempDir dir;
  const auto p = dir / "one.gsd";
  const HoomdFrame f = make_frame(123456789012345ull, 7, 1);
  {
    auto w = HoomdWriter::create(p);
    w.write_frame(f);
  }
  const Reader r(p);
  EXPECT_EQ(r.application(), "hardbody");
  EXPECT_EQ(r.schema(), "hoomd");
  EXPECT_EQ(r.schema_version(), (Version{1, 4}));
  EXPECT_EQ(r.read<double>(0, "log/particles/hardbody/position_double", 7, 3),
            f.log.at("particles/hardbody/position_double").values);
  const Array<std::int8_t> types = r.read<std::int8_t>(0, "particles/types");
  EXPECT_EQ(types.N, 3u);
  EXPECT_EQ(types.M, 13u);  // "superquadric" + terminator
  expect_frames_equal(read_frame(r, 0), f);
  expect_frames_equal(read_last_frame(p), f);
}

TEST(GsdHoomd, DefaultsAreOmittedAndReadBack) {
  TempDir dir;
  const auto p = dir / "defaults.gsd";
  HoomdFrame f;
  f.N = 2;
  f.box = {3, 3, 3, 0, 0, 0};
  f.position = {0.5f, 0.25f, 0.0f, -1.0f, 1.0f, 1.5f};
  f.orientation = {1, 0, 0, 0, 1, 0, 0, 0};  // identity: equal to the default
  f.type_id = {0, 0};
  f.types = {"A"};
  {
    auto w = HoomdWriter::create(p);
    w.write_frame(f);
  }
  const Reader r(p);
  for (const char* name : {"particles/orientation", "particles/typeid", "particles/types",
                           "particles/velocity", "configuration/dimensions"})
    EXPECT_FALSE(r.has(0, name)) << name;
  for (const char* name : {"configuration/step", "configuration/box", "particles/N",
                           "particles/position"})
    EXPECT_TRUE(r.has(0, name)) << name;
  const HoomdFrame g = read_frame(r, 0);
  EXPECT_EQ(g.orientation, f.orientation);
  EXPECT_EQ(g.type_id, f.type_id);
  EXPECT_EQ(g.types, f.types);
  EXPECT_EQ(g.velocity, std::vector<float>(6, 0.0f));
  EXPECT_EQ(g.angmom, std::vector<float>(8, 0.0f));
  EXPECT_EQ(g.image, std::vector<std::int32_t>(6, 0));
  EXPECT_TRUE(g.type_shapes.empty());
  EXPECT_EQ(g.dimensions, 3);
}

TEST(GsdHoomd, LaterFramesLeaveOutWhatFrameZeroDefines) {
  TempDir dir;
  const auto p = dir / "multi.gsd";
  std::vector<HoomdFrame> frames{make_frame(0, 5, 1), make_frame(10, 5, 2), make_frame(20, 3, 3),
                                 make_frame(30, 3, 4)};
  frames[1].velocity = frames[0].velocity;
  frames[1].type_id = frames[0].type_id;
  // N changes in frame 2: identity orientations now match the schema default, not frame 0.
  test::set_identity_orientations(frames[2]);
  {
    auto w = HoomdWriter::create(p);
    for (const auto& f : frames) w.write_frame(f);
    EXPECT_EQ(w.nframes(), 4u);
  }
  const Reader r(p);
  ASSERT_EQ(r.nframes(), 4u);
  for (const char* name : {"particles/types", "particles/type_shapes", "particles/typeid",
                           "particles/velocity"})
    EXPECT_FALSE(r.has(1, name)) << name;
  EXPECT_TRUE(r.has(1, "particles/orientation"));
  EXPECT_FALSE(r.has(2, "particles/orientation"));
  EXPECT_TRUE(r.has(2, "particles/typeid"));  // N differs: frame 0's typeid does not apply
  for (std::uint64_t i = 0; i < frames.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_TRUE(r.has(i, "log/hardbody/time"));
    expect_frames_equal(read_frame(r, i), frames[i]);
  }
  expect_error<std::runtime_error>([&] { (void)read_frame(r, 4); },
                                   {p.string(), "no frame 4", "4 frames"});
}

TEST(GsdHoomd, AppendGivesTheSameFileAsOneSession) {
  TempDir dir;
  std::vector<HoomdFrame> frames{make_frame(0, 4, 1), make_frame(10, 4, 2), make_frame(20, 6, 3)};
  frames[1].types = frames[0].types;
  {
    auto w = HoomdWriter::create(dir / "one.gsd");
    for (const auto& f : frames) w.write_frame(f);
  }
  {
    auto w = HoomdWriter::create(dir / "two.gsd");
    w.write_frame(frames[0]);
  }
  for (std::size_t i = 1; i < frames.size(); ++i) {
    auto w = HoomdWriter::append(dir / "two.gsd");
    EXPECT_EQ(w.nframes(), i);
    w.write_frame(frames[i]);
  }
  EXPECT_EQ(file_bytes(dir / "one.gsd"), file_bytes(dir / "two.gsd"));
  const Reader r(dir / "two.gsd");
  for (std::uint64_t i = 0; i < frames.size(); ++i) expect_frames_equal(read_frame(r, i), frames[i]);
}

TEST(GsdHoomd, InvalidFramesAreRejectedBeforeWriting) {
  TempDir dir;
  const auto p = dir / "invalid.gsd";
  auto w = HoomdWriter::create(p);
  const HoomdFrame good = make_frame(0, 4, 1);
  auto rejected = [&](auto mutate, std::initializer_list<std::string> fragments) {
    HoomdFrame f = good;
    mutate(f);
    expect_error<std::invalid_argument>([&] { w.write_frame(f); }, fragments);
  };
  rejected([](HoomdFrame& f) { f.position.pop_back(); }, {p.string(), "position", "11 values"});
  rejected([](HoomdFrame& f) { f.orientation.resize(3); }, {"orientation"});
  rejected([](HoomdFrame& f) { f.type_id[2] = 3; }, {"type_id 3", "3 types"});
  rejected([](HoomdFrame& f) { f.type_shapes[1] = "{not json"; }, {"not a JSON object"});
  rejected([](HoomdFrame& f) { f.type_shapes.pop_back(); }, {"2 type_shapes for 3 types"});
  rejected([](HoomdFrame& f) { f.dimensions = 4; }, {"dimensions = 4"});
  rejected([](HoomdFrame& f) { f.types[0] = ""; }, {"type name"});
  rejected([](HoomdFrame& f) { f.log["x"] = LogArray{2, 2, {1.0}}; }, {"log 'x'", "1 values"});
  w.write_frame(good);
  rejected([](HoomdFrame& f) { f.log["hardbody/new"] = LogArray{1, 1, {1.0}}; },
           {"log 'hardbody/new' is not in frame 0"});
  // Frame 1 without types: frame 0's three types are in force, so type_id 2 is fine.
  HoomdFrame next = make_frame(1, 4, 2);
  next.types.clear();
  next.type_shapes.clear();
  w.write_frame(next);
  w.close();
  const Reader r(p);
  EXPECT_EQ(r.nframes(), 2u);
  EXPECT_EQ(read_frame(r, 1).types, good.types);
}

TEST(GsdHoomd, WrongSchemaIsRefused) {
  TempDir dir;
  const auto p = dir / "other.gsd";
  {
    Writer w = Writer::create(p, "someone", "other", {1, 0});
    w.write_chunk<float>("x", 1, 1, std::vector<float>{1});
    w.end_frame();
  }
  expect_error<std::runtime_error>([&] { (void)read_frame(p, 0); },
                                   {p.string(), "schema is 'other'", "expected 'hoomd'"});
  expect_error<std::runtime_error>([&] { (void)HoomdWriter::append(p); },
                                   {p.string(), "expected 'hoomd'"});
}

TEST(GsdHoomd, WrongChunkTypeInAFileIsNamed) {
  TempDir dir;
  const auto p = dir / "badtype.gsd";
  {
    Writer w = Writer::create(p, "someone", "hoomd", kHoomdSchemaVersion);
    w.write_chunk<std::uint32_t>("particles/N", 1, 1, std::vector<std::uint32_t>{2});
    w.write_chunk<double>("particles/position", 2, 3, std::vector<double>(6, 0.0));
    w.end_frame();
  }
  expect_error<std::runtime_error>([&] { (void)read_frame(p, 0); },
                                   {p.string(), "particles/position", "float64", "float32"});
}

TEST(GsdHoomd, EmptyFrame) {
  TempDir dir;
  const auto p = dir / "empty.gsd";
  HoomdFrame f;
  f.log["hardbody/time"] = LogArray{1, 1, {2.5}};
  write_frame_atomic(p, f);
  const HoomdFrame g = read_last_frame(p);
  EXPECT_EQ(g.N, 0u);
  EXPECT_TRUE(g.position.empty());
  EXPECT_EQ(g.log.at("hardbody/time").values, std::vector<double>{2.5});
}

TEST(GsdHoomd, AtomicCheckpointReplacesOrKeepsTheOldFile) {
  TempDir dir;
  const auto p = dir / "checkpoint.gsd";
  auto tmp = p;
  tmp += ".tmp";
  write_frame_atomic(p, make_frame(1, 3, 1));
  const HoomdFrame second = make_frame(2, 4, 2);
  write_frame_atomic(p, second);
  expect_frames_equal(read_last_frame(p), second);
  EXPECT_EQ(Reader(p).nframes(), 1u);
  EXPECT_FALSE(std::filesystem::exists(tmp));

  // A frame that cannot be written: the old checkpoint survives byte for byte.
  const auto before = file_bytes(p);
  HoomdFrame bad = make_frame(3, 4, 3);
  bad.type_id[0] = 99;
  expect_error<std::invalid_argument>([&] { write_frame_atomic(p, bad); }, {"type_id 99"});
  EXPECT_EQ(file_bytes(p), before);
  EXPECT_FALSE(std::filesystem::exists(tmp));

  // A directory that does not exist: a clear error, nothing created.
  const auto nowhere = dir / "missing" / "checkpoint.gsd";
  expect_error<std::runtime_error>([&] { write_frame_atomic(nowhere, second); },
                                   {"missing", "cannot create"});
  EXPECT_FALSE(std::filesystem::exists(dir / "missing"));

  // A stale temporary file from an earlier crash does not get in the way.
  std::ofstream(tmp) << "left over";
  write_frame_atomic(p, make_frame(4, 2, 4));
  EXPECT_EQ(read_last_frame(p).step, 4u);
  EXPECT_FALSE(std::filesystem::exists(tmp));
}

TEST(GsdHoomd, ShapeJsonKeepsFullPrecision) {
  const auto e = nlohmann::json::parse(ellipsoid_shape(0.1, 1.0 / 3.0, 2e-300));
  EXPECT_EQ(e["type"], "Ellipsoid");
  EXPECT_EQ(e["a"].get<double>(), 0.1);
  EXPECT_EQ(e["b"].get<double>(), 1.0 / 3.0);
  EXPECT_EQ(e["c"].get<double>(), 2e-300);
  const auto s = nlohmann::json::parse(sphere_shape(2.5));
  EXPECT_EQ(s["type"], "Sphere");
  EXPECT_EQ(s["diameter"].get<double>(), 2.5);
  const auto c = nlohmann::json::parse(convex_polyhedron_shape({{1, 2, 3}, {4, 5, 6}}, 0.5));
  EXPECT_EQ(c["type"], "ConvexPolyhedron");
  EXPECT_EQ(c["vertices"][1][2].get<double>(), 6.0);
  EXPECT_EQ(c["rounding_radius"].get<double>(), 0.5);
}

}  // namespace
}  // namespace hb::gsd
