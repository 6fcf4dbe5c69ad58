// HOOMD-schema frames over the GSD file layer; see gsd_hoomd.hpp for the rules.
#include "io/gsd_hoomd.hpp"

#include "core/fault_injection.hpp"

#include <unistd.h>
#include <fcntl.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>

#include "observers/overlap_sampling.hpp"  // fibonacci_sphere
#include "shapes/superquadric.hpp"

namespace hb::gsd {

namespace {

constexpr std::string_view kLogPrefix = "log/";

// Chunk names.
constexpr const char* kStep = "configuration/step";
constexpr const char* kDimensions = "configuration/dimensions";
constexpr const char* kBox = "configuration/box";
constexpr const char* kN = "particles/N";
constexpr const char* kTypes = "particles/types";
constexpr const char* kTypeShapes = "particles/type_shapes";
constexpr const char* kTypeId = "particles/typeid";
constexpr const char* kDiameter = "particles/diameter";
constexpr const char* kPosition = "particles/position";
constexpr const char* kOrientation = "particles/orientation";
constexpr const char* kVelocity = "particles/velocity";
constexpr const char* kAngmom = "particles/angmom";
constexpr const char* kImage = "particles/image";

template <class T>
ChunkSource one_value(T v) {
  return owned_source(std::vector<T>{v}, 1);
}
// NT strings as an int8 NT x M array of 0-terminated rows, M = longest + 1.
EncodedChunk encode_strings(const std::vector<std::string>& s) {
  std::size_t width = 0;
  for (const auto& x : s) width = std::max(width, x.size() + 1);
  EncodedChunk e{Type::int8, s.size(), static_cast<std::uint32_t>(width),
                 std::vector<std::byte>(s.size() * width)};
  for (std::size_t i = 0; i < s.size(); ++i)
    std::memcpy(e.bytes.data() + i * width, s[i].data(), s[i].size());
  return e;
}

// How a chunk may be left out of a frame i > 0.
enum class Fallback {
  none,          // always written
  global,        // frame 0's chunk stands in whatever N is (configuration, types, shapes)
  per_particle,  // frame 0's chunk stands in only when N equals frame 0's N
};

struct Planned {
  std::string name;
  ChunkSource src;
  Fallback fallback;
  std::vector<std::byte> default_row;  // the schema default of every row; empty: none
};

template <class T>
std::vector<std::byte> row_bytes(std::initializer_list<T> row) {
  std::vector<std::byte> out(row.size() * sizeof(T));
  std::memcpy(out.data(), row.begin(), out.size());
  return out;
}

ChunkSource owned_source(EncodedChunk e) {
  auto keep = std::make_shared<const EncodedChunk>(std::move(e));
  return ChunkSource{keep->type, keep->N, keep->M, keep->bytes.empty() ? nullptr : keep->bytes.data(),
                     {}, keep};
}

// Calls fn(bytes, rows) on successive whole rows of src, about `limit` bytes at a time (values in
// memory are passed in place), until fn returns false. Returns false if fn did.
template <class Fn>
bool for_each_piece(const ChunkSource& src, std::size_t limit, Fn&& fn) {
  const std::size_t row = src.row_bytes();
  if (src.N == 0 || row == 0) return true;
  const std::uint64_t step = std::max<std::uint64_t>(limit / row, 1);
  std::vector<std::byte> scratch;
  if (!src.data) scratch.resize(std::min<std::uint64_t>(step, src.N) * row);
  for (std::uint64_t first = 0; first < src.N; first += step) {
    const std::uint64_t n = std::min(step, src.N - first);
    const std::byte* p = nullptr;
    if (src.data) {
      p = static_cast<const std::byte*>(src.data) + first * row;
    } else {
      src.fill(first, n, scratch.data());
      p = scratch.data();
    }
    if (!fn(p, n)) return false;
  }
  return true;
}

[[noreturn]] void bad_frame(const std::filesystem::path& path, std::string_view what) {
  throw std::invalid_argument(fmt::format("{}: invalid HOOMD frame: {}", path.string(), what));
}

void check_size(const std::filesystem::path& path, std::string_view field, std::size_t size,
                std::uint64_t N, std::uint32_t M, bool optional) {
  if (optional && size == 0) return;
  if (size != N * M)
    bad_frame(path, fmt::format("{} has {} values, expected N x {} = {}", field, size, M, N * M));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Shapes

std::string sphere_shape(double diameter) {
  return nlohmann::json{{"type", "Sphere"}, {"diameter", diameter}}.dump();
}

std::string ellipsoid_shape(double a, double b, double c) {
  return nlohmann::json{{"type", "Ellipsoid"}, {"a", a}, {"b", b}, {"c", c}}.dump();
}

std::string convex_polyhedron_shape(const std::vector<std::array<double, 3>>& vertices,
                                    double rounding_radius) {
  return nlohmann::json{{"type", "ConvexPolyhedron"},
                        {"rounding_radius", rounding_radius},
                        {"vertices", vertices}}
      .dump();
}

std::string superquadric_shape(const std::array<double, 3>& semi_axes,
                               const std::array<double, 3>& exponents, int vertices) {
  const Superquadric s{semi_axes[0], semi_axes[1], semi_axes[2],
                       exponents[0], exponents[1], exponents[2]};
  const int half = std::max(vertices / 2, 4);
  std::vector<std::array<double, 3>> v;
  v.reserve(2 * std::size_t(half));
  auto put = [&](const Vec3& x) { v.push_back({x.x(), x.y(), x.z()}); };
  for (const Vec3& n : sampling_detail::fibonacci_sphere(half)) {
    put(s.ray_surface(s.axes().cwiseProduct(n)));
    put(s.support_point(n));
  }
  return convex_polyhedron_shape(v);
}

// ---------------------------------------------------------------------------------------------
// Writer

HoomdWriter HoomdWriter::create(const std::filesystem::path& path) {
  return HoomdWriter(Writer::create(path, kApplication, "hoomd", kHoomdSchemaVersion));
}

HoomdWriter HoomdWriter::append(const std::filesystem::path& path) {
  const Reader r(path);
  if (r.schema() != "hoomd" || r.schema_version().major != 1)
    throw std::runtime_error(fmt::format("{}: schema is '{}' {}.{}, expected 'hoomd' 1.x",
                                         path.string(), r.schema(), r.schema_version().major,
                                         r.schema_version().minor));
  HoomdWriter w(Writer::append(path, "hoomd"));
  if (r.nframes() == 0) return w;
  // Later frames are written against frame 0, so learn where frame 0's chunks are.
  if (r.has(0, kN)) w.frame0_N_ = r.read<std::uint32_t>(0, kN, 1, 1)[0];
  for (const char* name : {kDimensions, kTypes, kTypeShapes, kTypeId, kDiameter, kOrientation,
                           kVelocity, kAngmom, kImage})
    if (const Chunk* c = r.find(0, name)) w.frame0_[name] = *c;
  for (const auto& name : r.names_with_prefix(kLogPrefix))
    if (r.has(0, name)) w.frame0_logs_.push_back(name.substr(kLogPrefix.size()));
  return w;
}

FrameSource frame_source(const HoomdFrame& f) {
  FrameSource s;
  s.step = f.step;
  s.dimensions = f.dimensions;
  s.box = f.box;
  s.N = f.N;
  s.position = memory_source(f.position, 3);
  s.orientation = memory_source(f.orientation, 4);
  s.type_id = memory_source(f.type_id, 1);
  s.diameter = memory_source(f.diameter, 1);
  s.velocity = memory_source(f.velocity, 3);
  s.angmom = memory_source(f.angmom, 4);
  s.image = memory_source(f.image, 3);
  s.types = f.types;
  s.type_shapes = f.type_shapes;
  for (const auto& [key, a] : f.log) {
    ChunkSource c = memory_source(a.values, a.cols == 0 ? 1 : a.cols);
    c.N = a.rows;
    c.M = a.cols;
    s.log.emplace(key, std::move(c));
  }
  return s;
}

void HoomdWriter::write_frame(const HoomdFrame& f) {
  const auto& path = file_.path();
  const std::uint64_t N = f.N;
  check_size(path, "position", f.position.size(), N, 3, false);
  check_size(path, "orientation", f.orientation.size(), N, 4, true);
  check_size(path, "type_id", f.type_id.size(), N, 1, true);
  check_size(path, "diameter", f.diameter.size(), N, 1, true);
  check_size(path, "velocity", f.velocity.size(), N, 3, true);
  check_size(path, "angmom", f.angmom.size(), N, 4, true);
  check_size(path, "image", f.image.size(), N, 3, true);
  for (const auto& [key, a] : f.log)
    if (a.cols == 0 || a.values.size() != a.rows * a.cols)
      bad_frame(path, fmt::format("log '{}' has {} values for {} x {}", key, a.values.size(),
                                  a.rows, a.cols));
  write_frame(frame_source(f));
}

bool HoomdWriter::same_as(const ChunkSource& src, const Chunk& c) {
  if (c.type != src.type || c.N != src.N || c.M != src.M) return false;
  std::vector<std::byte> stored;
  std::uint64_t offset = c.location;
  return for_each_piece(src, file_.buffer_size(), [&](const std::byte* p, std::uint64_t rows) {
    const std::size_t n = rows * src.row_bytes();
    stored.resize(n);
    file_.read_back(offset, n, stored.data());
    offset += n;
    return std::memcmp(p, stored.data(), n) == 0;
  });
}

bool HoomdWriter::same_as(const ChunkSource& src, const std::vector<std::byte>& row) {
  if (row.size() != src.row_bytes()) return false;
  return for_each_piece(src, file_.buffer_size(), [&](const std::byte* p, std::uint64_t rows) {
    for (std::uint64_t i = 0; i < rows; ++i)
      if (std::memcmp(p + i * row.size(), row.data(), row.size()) != 0) return false;
    return true;
  });
}

void HoomdWriter::write_frame(const FrameSource& f) {
  const auto& path = file_.path();
  const std::uint64_t N = f.N;
  const bool first = nframes() == 0;

  // Validate everything before the first byte goes out.
  if (f.dimensions != 2 && f.dimensions != 3)
    bad_frame(path, fmt::format("dimensions = {}, must be 2 or 3", int{f.dimensions}));
  const auto check = [&](std::string_view field, const ChunkSource& c, Type type, std::uint32_t M,
                         bool optional) {
    if (optional && !c.given()) return;
    if (!c.given() && N > 0) bad_frame(path, fmt::format("{} is missing", field));
    if (c.type != type || c.M != M || c.N != N)
      bad_frame(path, fmt::format("{} is {} x {} {}, expected N x {} {} (N = {})", field, c.N, c.M,
                                  type_name(c.type), M, type_name(type), N));
  };
  check("position", f.position, Type::float32, 3, N == 0);
  check("orientation", f.orientation, Type::float32, 4, true);
  check("type_id", f.type_id, Type::uint32, 1, true);
  check("diameter", f.diameter, Type::float32, 1, true);
  check("velocity", f.velocity, Type::float32, 3, true);
  check("angmom", f.angmom, Type::float32, 4, true);
  check("image", f.image, Type::int32, 3, true);
  for (const auto& t : f.types)
    if (t.empty() || t.find('\0') != std::string::npos)
      bad_frame(path, fmt::format("type name '{}' is empty or contains a 0 byte", t));
  // Types in force: this frame's, else frame 0's (a reader falls back to them), else {"A"}.
  std::uint64_t NT = f.types.size();
  if (NT == 0) {
    const auto it = frame0_.find(kTypes);
    NT = (!first && it != frame0_.end()) ? it->second.N : 1;
  }
  if (f.type_id.given())
    for_each_piece(f.type_id, file_.buffer_size(), [&](const std::byte* p, std::uint64_t rows) {
      for (std::uint64_t i = 0; i < rows; ++i) {
        std::uint32_t id;
        std::memcpy(&id, p + 4 * i, 4);
        if (id >= NT) bad_frame(path, fmt::format("type_id {} but there are {} types", id, NT));
      }
      return true;
    });
  if (!f.type_shapes.empty() && f.type_shapes.size() != NT)
    bad_frame(path, fmt::format("{} type_shapes for {} types", f.type_shapes.size(), NT));
  for (const auto& s : f.type_shapes) {
    const auto j = nlohmann::json::parse(s, nullptr, false);
    if (j.is_discarded() || !j.is_object() || s.find('\0') != std::string::npos)
      bad_frame(path, fmt::format("type_shapes entry '{}' is not a JSON object", s));
  }
  for (const auto& [key, a] : f.log) {
    if (key.empty()) bad_frame(path, "empty log key");
    if (a.M == 0 || type_size(a.type) == 0 || a.type == Type::character || (a.N > 0 && !a.given()))
      bad_frame(path, fmt::format("log '{}' ({} x {} {}) has no values", key, a.N, a.M,
                                  type_name(a.type)));
    if (!first && std::find(frame0_logs_.begin(), frame0_logs_.end(), key) == frame0_logs_.end())
      bad_frame(path, fmt::format("log '{}' is not in frame 0 (the hoomd schema requires every "
                                  "log chunk to be present in frame 0)", key));
  }

  // What this frame holds, in schema order.
  std::vector<Planned> plan;
  plan.push_back({kStep, one_value(f.step), Fallback::none, {}});
  plan.push_back({kDimensions, one_value(f.dimensions), Fallback::global, row_bytes<std::uint8_t>({3})});
  plan.push_back({kBox, owned_source(std::vector<float>(f.box.begin(), f.box.end()), 1),
                  Fallback::none, {}});
  plan.push_back({kN, one_value(f.N), Fallback::none, {}});
  if (!f.types.empty()) {
    // The default {"A"} is one row "A\0"; a reader sees it only when types is absent.
    plan.push_back({kTypes, owned_source(encode_strings(f.types)), Fallback::global,
                    f.types == std::vector<std::string>{"A"} ? row_bytes<std::int8_t>({'A', 0})
                                                             : std::vector<std::byte>{}});
  }
  if (!f.type_shapes.empty())
    plan.push_back({kTypeShapes, owned_source(encode_strings(f.type_shapes)), Fallback::global, {}});
  if (f.type_id.given())
    plan.push_back({kTypeId, f.type_id, Fallback::per_particle, row_bytes<std::uint32_t>({0})});
  if (f.diameter.given())
    plan.push_back({kDiameter, f.diameter, Fallback::per_particle, row_bytes<float>({1})});
  if (N > 0) plan.push_back({kPosition, f.position, Fallback::none, {}});
  if (f.orientation.given())
    plan.push_back({kOrientation, f.orientation, Fallback::per_particle,
                    row_bytes<float>({1, 0, 0, 0})});
  if (f.velocity.given())
    plan.push_back({kVelocity, f.velocity, Fallback::per_particle, row_bytes<float>({0, 0, 0})});
  if (f.angmom.given())
    plan.push_back({kAngmom, f.angmom, Fallback::per_particle, row_bytes<float>({0, 0, 0, 0})});
  if (f.image.given())
    plan.push_back({kImage, f.image, Fallback::per_particle, row_bytes<std::int32_t>({0, 0, 0})});
  for (const auto& [key, a] : f.log)
    plan.push_back({std::string(kLogPrefix) + key, a, Fallback::none, {}});

  // Leave out what a reader reconstructs exactly: frame 0's chunk or the schema default.
  for (const Planned& p : plan) {
    if (p.fallback != Fallback::none) {
      bool omit = false;
      const auto it = first ? frame0_.end() : frame0_.find(p.name);
      if (it != frame0_.end() && (p.fallback == Fallback::global || N == frame0_N_))
        omit = same_as(p.src, it->second);
      else if (!p.default_row.empty())
        omit = same_as(p.src, p.default_row);
      if (omit) continue;
    }
    const ChunkSource& c = p.src;
    const std::uint64_t at = c.fill ? file_.write_chunk(p.name, c.type, c.N, c.M, c.fill)
                                    : file_.write_chunk(p.name, c.type, c.N, c.M, c.data);
    if (first && p.fallback != Fallback::none)
      frame0_[p.name] = Chunk{0, c.N, at, c.M, 0, c.type};
  }
  file_.end_frame();
  if (first) {
    frame0_N_ = f.N;
    for (const auto& [key, a] : f.log) frame0_logs_.push_back(key);
  }
}

// ---------------------------------------------------------------------------------------------
// Reader

namespace {

class FrameReader {
 public:
  FrameReader(const Reader& r, std::uint64_t frame) : r_(r), frame_(frame) {}

  const std::filesystem::path& path() const { return r_.path(); }

  // The chunk that defines `name` in this frame: its own, frame 0's, or none (default).
  const Chunk* pick(const std::string& name, Fallback fallback, std::uint64_t N,
                    std::uint64_t N0) const {
    if (const Chunk* c = r_.find(frame_, name)) return c;
    if (frame_ == 0 || fallback == Fallback::none) return nullptr;
    if (fallback == Fallback::per_particle && N != N0) return nullptr;
    return r_.find(0, name);
  }

  template <class T>
  std::vector<T> read(const Chunk& c, std::uint64_t N, std::uint32_t M) const {
    return r_.read<T>(c.frame, r_.names()[c.id], N, M);
  }

  // Per-particle array: from the file or filled with the default row.
  template <class T>
  std::vector<T> particles(const std::string& name, std::uint64_t N, std::uint64_t N0,
                           const std::vector<T>& row) const {
    const auto M = static_cast<std::uint32_t>(row.size());
    if (const Chunk* c = pick(name, Fallback::per_particle, N, N0)) return read<T>(*c, N, M);
    std::vector<T> out;
    out.reserve(N * M);
    for (std::uint64_t i = 0; i < N; ++i) out.insert(out.end(), row.begin(), row.end());
    return out;
  }

  std::vector<std::string> strings(const Chunk& c) const {
    if (c.type != Type::int8 && c.type != Type::uint8 && c.type != Type::character)
      throw std::runtime_error(fmt::format("{}: chunk '{}' of frame {} has type {}, expected int8",
                                           path().string(), r_.names()[c.id], c.frame,
                                           type_name(c.type)));
    const auto bytes = r_.read_bytes(c);
    std::vector<std::string> out;
    for (std::uint64_t i = 0; i < c.N; ++i) {
      const char* row = reinterpret_cast<const char*>(bytes.data()) + i * c.M;
      out.emplace_back(row, strnlen(row, c.M));
    }
    return out;
  }

  LogArray log(const Chunk& c) const {
    const auto bytes = r_.read_bytes(c);
    LogArray a{c.N, c.M, std::vector<double>(c.N * c.M)};
    const std::byte* p = bytes.data();
    auto convert = [&]<class T>(T) {
      for (std::size_t i = 0; i < a.values.size(); ++i) {
        T v;
        std::memcpy(&v, p + i * sizeof(T), sizeof(T));
        a.values[i] = static_cast<double>(v);
      }
    };
    switch (c.type) {
      case Type::uint8: convert(std::uint8_t{}); break;
      case Type::uint16: convert(std::uint16_t{}); break;
      case Type::uint32: convert(std::uint32_t{}); break;
      case Type::uint64: convert(std::uint64_t{}); break;
      case Type::int8: convert(std::int8_t{}); break;
      case Type::int16: convert(std::int16_t{}); break;
      case Type::int32: convert(std::int32_t{}); break;
      case Type::int64: convert(std::int64_t{}); break;
      case Type::float32: convert(float{}); break;
      case Type::float64: convert(double{}); break;
      case Type::character:
        throw std::runtime_error(fmt::format(
            "{}: log chunk '{}' of frame {} is text; hardbody reads numeric logs only",
            path().string(), r_.names()[c.id], c.frame));
    }
    return a;
  }

 private:
  const Reader& r_;
  std::uint64_t frame_;
};

}  // namespace

HoomdFrame read_frame(const Reader& r, std::uint64_t frame) {
  const std::string path = r.path().string();
  if (r.schema() != "hoomd" || r.schema_version().major != 1)
    throw std::runtime_error(fmt::format("{}: schema is '{}' {}.{}, expected 'hoomd' 1.x", path,
                                         r.schema(), r.schema_version().major,
                                         r.schema_version().minor));
  if (frame >= r.nframes())
    throw std::runtime_error(fmt::format("{}: no frame {} (the file has {} frames)", path, frame,
                                         r.nframes()));
  const FrameReader fr(r, frame);
  const FrameReader f0(r, 0);
  HoomdFrame f;

  std::uint64_t N0 = 0;
  if (const Chunk* c = f0.pick(kN, Fallback::none, 0, 0)) N0 = f0.read<std::uint32_t>(*c, 1, 1)[0];
  const Chunk* cn = fr.pick(kN, Fallback::global, 0, 0);
  f.N = cn ? fr.read<std::uint32_t>(*cn, 1, 1)[0] : 0;
  const std::uint64_t N = f.N;

  if (const Chunk* c = fr.pick(kStep, Fallback::global, N, N0))
    f.step = fr.read<std::uint64_t>(*c, 1, 1)[0];
  if (const Chunk* c = fr.pick(kDimensions, Fallback::global, N, N0))
    f.dimensions = fr.read<std::uint8_t>(*c, 1, 1)[0];
  if (const Chunk* c = fr.pick(kBox, Fallback::global, N, N0)) {
    if (c->N * c->M != 6)
      throw std::runtime_error(fmt::format("{}: chunk '{}' of frame {} has {} x {} values, "
                                           "expected 6", path, kBox, c->frame, c->N, c->M));
    const auto box = fr.read<float>(*c, c->N, c->M);
    std::copy(box.begin(), box.end(), f.box.begin());
  }

  const Chunk* ct = fr.pick(kTypes, Fallback::global, N, N0);
  f.types = ct ? fr.strings(*ct) : std::vector<std::string>{"A"};
  if (f.types.empty())
    throw std::runtime_error(fmt::format("{}: frame {} defines no particle types", path, frame));
  if (const Chunk* c = fr.pick(kTypeShapes, Fallback::global, N, N0)) {
    f.type_shapes = fr.strings(*c);
    for (const auto& s : f.type_shapes)
      if (!nlohmann::json::accept(s))
        throw std::runtime_error(fmt::format("{}: frame {}: type_shapes entry '{}' is not JSON",
                                             path, frame, s));
  }

  f.type_id = fr.particles<std::uint32_t>(kTypeId, N, N0, {0});
  for (std::uint32_t id : f.type_id)
    if (id >= f.types.size())
      throw std::runtime_error(fmt::format("{}: frame {}: typeid {} but only {} types", path,
                                           frame, id, f.types.size()));
  f.diameter = fr.particles<float>(kDiameter, N, N0, {1});
  f.position = fr.particles<float>(kPosition, N, N0, {0, 0, 0});
  f.orientation = fr.particles<float>(kOrientation, N, N0, {1, 0, 0, 0});
  f.velocity = fr.particles<float>(kVelocity, N, N0, {0, 0, 0});
  f.angmom = fr.particles<float>(kAngmom, N, N0, {0, 0, 0, 0});
  f.image = fr.particles<std::int32_t>(kImage, N, N0, {0, 0, 0});

  for (const auto& name : r.names_with_prefix(kLogPrefix))
    if (const Chunk* c = fr.pick(name, Fallback::global, N, N0))
      f.log[name.substr(kLogPrefix.size())] = fr.log(*c);
  return f;
}

HoomdFrame read_frame(const std::filesystem::path& path, std::uint64_t frame) {
  return read_frame(Reader(path), frame);
}

HoomdFrame read_last_frame(const std::filesystem::path& path) {
  const Reader r(path);
  if (r.nframes() == 0)
    throw std::runtime_error(fmt::format("{}: the file has no frames", path.string()));
  return read_frame(r, r.nframes() - 1);
}

// ---------------------------------------------------------------------------------------------
// Atomic single-frame files

namespace {

// Make a finished rename durable: fsync the directory holding the file.
void sync_directory(const std::filesystem::path& file) {
  const auto dir = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;  // the rename itself is done; durability is best effort here
  (void)::fsync(fd);
  ::close(fd);
}

}  // namespace

namespace {

template <class Frame>
void write_atomic(const std::filesystem::path& path, const Frame& frame, std::size_t buffer_size) {
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  try {
    HoomdWriter w = HoomdWriter::create(tmp);
    if (buffer_size > 0) w.set_buffer_size(buffer_size);
    w.write_frame(frame);
    fault_point("checkpoint-write");  // tests: a kill here must leave the previous file usable
    w.sync();
    w.close();
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec)
      throw std::runtime_error(fmt::format("{}: cannot rename {} over it: {}", path.string(),
                                           tmp.string(), ec.message()));
  } catch (const std::runtime_error& e) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error(fmt::format("{} (the previous {} is unchanged)", e.what(),
                                         path.filename().string()));
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
  sync_directory(path);
}

}  // namespace

void write_frame_atomic(const std::filesystem::path& path, const HoomdFrame& frame) {
  write_atomic(path, frame, 0);
}

void write_frame_atomic(const std::filesystem::path& path, const FrameSource& frame,
                        std::size_t buffer_size) {
  write_atomic(path, frame, buffer_size);
}

}  // namespace hb::gsd
