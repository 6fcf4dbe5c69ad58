// HOOMD-schema (version 1.4) frames on top of the GSD file layer: the trajectory and checkpoint
// format of hardbody, readable by gsd.hoomd, OVITO, freud, HOOMD-blue.
//
// Schema rules followed here:
//  * A chunk missing from frame i > 0 means "as in frame 0" (per-particle arrays: only when N
//    equals frame 0's N), otherwise the schema default. The writer omits a chunk only when a
//    reader applying this rule gets exactly the same bytes back; step, box, N, position and all
//    log chunks are written in every frame.
//  * particles/types and particles/type_shapes are int8 NT x M arrays of 0-terminated UTF-8
//    strings (M = longest + 1); type_shapes rows are JSON objects (see gsd "Shape Visualization").
//  * A log/ chunk present in some frame must be present in frame 0.
#pragma once
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string_view>
#include <string>
#include <vector>

#include <cstring>

#include "io/gsd.hpp"

namespace hb::gsd {

inline constexpr Version kHoomdSchemaVersion{1, 4};
inline constexpr std::string_view kApplication = "hardbody";

// A logged quantity: rows x cols doubles, row-major (stored as a float64 chunk "log/<key>").
struct LogArray {
  std::uint64_t rows = 1;
  std::uint32_t cols = 1;
  std::vector<double> values;
};

// One frame. Per-particle arrays are row-major, N rows. For writing, an empty optional array
// means "not given" (nothing written; a reader sees frame 0's value or the default). read_frame
// always fills every per-particle array (from the file, frame 0 or the schema default).
struct HoomdFrame {
  std::uint64_t step = 0;
  std::uint8_t dimensions = 3;
  std::array<float, 6> box{1, 1, 1, 0, 0, 0};  // Lx, Ly, Lz, xy, xz, yz
  std::uint32_t N = 0;
  std::vector<float> position;            // N x 3, required
  std::vector<float> orientation;         // N x 4, [w, x, y, z]; default 1,0,0,0
  std::vector<std::uint32_t> type_id;     // N (chunk particles/typeid); default 0
  std::vector<std::string> types;         // NT names; default {"A"}
  std::vector<std::string> type_shapes;   // NT JSON objects; empty = none defined
  std::vector<float> diameter;            // N; default 1 (bounding diameter; OVITO's sphere size)
  std::vector<float> velocity;            // N x 3; default 0
  std::vector<float> angmom;              // N x 4; default 0
  std::vector<std::int32_t> image;        // N x 3; default 0
  std::map<std::string, LogArray> log;    // key without the "log/" prefix, e.g. "hardbody/time"
};

// type_shapes entries (JSON with round-trip precision).
std::string sphere_shape(double diameter);
std::string ellipsoid_shape(double a, double b, double c);
std::string convex_polyhedron_shape(const std::vector<std::array<double, 3>>& vertices,
                                    double rounding_radius = 0.0);
// The schema has no superquadric: a ConvexPolyhedron whose `vertices` are surface points of the
// body |x/a|^n + |y/b|^m + |z/c|^p <= 1 (half along rays through a stretched Fibonacci sphere,
// half the support points of Fibonacci normals, which crowd where the surface bends: edges and
// corners), so OVITO and HOOMD's viewers draw the body's convex hull.
std::string superquadric_shape(const std::array<double, 3>& semi_axes,
                               const std::array<double, 3>& exponents, int vertices = 400);

// The values of one chunk for streaming writes: either all N x M values in memory (`data`,
// kept alive by `owner` when the source owns them), or rows made on demand by `fill` (a buffer's
// worth at a time). A source with neither is "not given".
struct ChunkSource {
  Type type = Type::float64;
  std::uint64_t N = 0;
  std::uint32_t M = 1;
  const void* data = nullptr;
  RowFill fill;
  std::shared_ptr<const void> owner;

  bool given() const { return data != nullptr || bool(fill); }
  std::size_t row_bytes() const { return std::size_t{M} * type_size(type); }
};

// A view of values in memory (v.size() / M rows); empty v gives a source that is not given.
template <class T>
ChunkSource memory_source(const std::vector<T>& v, std::uint32_t M) {
  return ChunkSource{type_of<T>(), v.size() / M, M, v.empty() ? nullptr : v.data(), {}, {}};
}
// A source that owns its values.
template <class T>
ChunkSource owned_source(std::vector<T> v, std::uint32_t M) {
  auto keep = std::make_shared<const std::vector<T>>(std::move(v));
  ChunkSource s = memory_source(*keep, M);
  s.owner = std::move(keep);
  return s;
}
inline ChunkSource owned_source(LogArray a) {
  ChunkSource s = owned_source(std::move(a.values), a.cols);
  s.N = a.rows;
  return s;
}
// N rows made on demand: row(i, T* out) writes the M values of row i.
template <class T, class RowFn>
ChunkSource row_source(std::uint64_t N, std::uint32_t M, RowFn row) {
  ChunkSource s{type_of<T>(), N, M, nullptr, {}, {}};
  s.fill = [M, row = std::move(row)](std::uint64_t first, std::uint64_t count, std::byte* out) {
    // Rows go through an aligned scratch row: `out` may be unaligned for T.
    T small[16];
    std::vector<T> large(M > 16 ? M : 0);
    T* buf = M > 16 ? large.data() : small;
    for (std::uint64_t i = 0; i < count; ++i) {
      row(first + i, buf);
      std::memcpy(out + i * M * sizeof(T), buf, M * sizeof(T));
    }
  };
  return s;
}

// A frame whose arrays are sources, for writing without a copy of the whole frame in memory.
// Per-particle sources must have N rows of the HOOMD type and width (position float32 x 3,
// orientation float32 x 4, type_id uint32 x 1, diameter float32 x 1, velocity float32 x 3,
// angmom float32 x 4, image int32 x 3); log sources may have any numeric type.
struct FrameSource {
  std::uint64_t step = 0;
  std::uint8_t dimensions = 3;
  std::array<float, 6> box{1, 1, 1, 0, 0, 0};
  std::uint32_t N = 0;
  ChunkSource position, orientation, type_id, diameter, velocity, angmom, image;
  std::vector<std::string> types;
  std::vector<std::string> type_shapes;
  std::map<std::string, ChunkSource> log;
};

// The sources of an in-memory frame (views: the frame must outlive them).
FrameSource frame_source(const HoomdFrame& f);

// A chunk as it goes to the file.
struct EncodedChunk {
  Type type = Type::uint8;
  std::uint64_t N = 0;
  std::uint32_t M = 1;
  std::vector<std::byte> bytes;
  friend bool operator==(const EncodedChunk&, const EncodedChunk&) = default;
};

// Appends HOOMD frames to a GSD file. Throws std::invalid_argument for an inconsistent frame
// (array sizes, typeid >= NT, a log key not in frame 0, ...) before anything is written.
class HoomdWriter {
 public:
  static HoomdWriter create(const std::filesystem::path& path);
  // Continue an existing hoomd-schema file (created by hardbody or any GSD 2.x writer).
  static HoomdWriter append(const std::filesystem::path& path);

  void write_frame(const HoomdFrame& frame);
  // The same bytes as write_frame(HoomdFrame) of the equal frame, streamed: memory is one buffer
  // (Writer::buffer_size), whatever N.
  void write_frame(const FrameSource& frame);
  void set_buffer_size(std::size_t bytes) { file_.set_buffer_size(bytes); }
  void sync() { file_.sync(); }
  void close() { file_.close(); }
  std::uint64_t nframes() const { return file_.frame(); }
  const std::filesystem::path& path() const { return file_.path(); }

 private:
  explicit HoomdWriter(Writer w) : file_(std::move(w)) {}

  // Does src hold exactly the bytes of `stand_in` (a chunk of frame 0 in the file) or of N
  // repetitions of `row` (a schema default)? Compared a buffer at a time.
  bool same_as(const ChunkSource& src, const Chunk& stand_in);
  bool same_as(const ChunkSource& src, const std::vector<std::byte>& row);

  Writer file_;
  std::map<std::string, Chunk> frame0_;          // frame 0's chunks that later frames may omit
  std::vector<std::string> frame0_logs_;         // log keys of frame 0
  std::uint32_t frame0_N_ = 0;
};

// Read frame `frame` of a hoomd-schema file, applying the schema's fallback rules. Throws
// std::runtime_error naming the file for a wrong schema, a frame out of range, a chunk of the
// wrong type or shape, typeid >= NT, or a type_shapes row that is not JSON.
HoomdFrame read_frame(const Reader& file, std::uint64_t frame);
HoomdFrame read_frame(const std::filesystem::path& path, std::uint64_t frame);
HoomdFrame read_last_frame(const std::filesystem::path& path);  // throws if there is no frame

// Write a complete one-frame file to path + ".tmp", flush it to disk and rename it over `path`.
// If anything fails, the temporary file is removed and the previous `path` is untouched.
// Write failures (ENOSPC, EIO, ...) throw std::runtime_error naming the file and the OS error.
void write_frame_atomic(const std::filesystem::path& path, const HoomdFrame& frame);
void write_frame_atomic(const std::filesystem::path& path, const FrameSource& frame,
                        std::size_t buffer_size = 0);  // 0: the Writer's default

}  // namespace hb::gsd
