// HOOMD-schema frames over the GSD file layer; see gsd_hoomd.hpp for the rules.
#include "io/gsd_hoomd.hpp"

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
EncodedChunk encode(const T* data, std::uint64_t N, std::uint32_t M) {
  EncodedChunk e{type_of<T>(), N, M, std::vector<std::byte>(N * M * sizeof(T))};
  if (!e.bytes.empty()) std::memcpy(e.bytes.data(), data, e.bytes.size());
  return e;
}
template <class T>
EncodedChunk encode(const std::vector<T>& v, std::uint32_t M) {
  return encode(v.data(), v.size() / M, M);
}
template <class T>
EncodedChunk repeated(std::uint64_t N, std::vector<T> row) {
  std::vector<T> all;
  all.reserve(N * row.size());
  for (std::uint64_t i = 0; i < N; ++i) all.insert(all.end(), row.begin(), row.end());
  return encode(all.data(), N, static_cast<std::uint32_t>(row.size()));
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
  EncodedChunk chunk;
  Fallback fallback;
  std::optional<EncodedChunk> schema_default;
};

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
  // Later frames are written against frame 0, so learn what frame 0 holds.
  if (r.has(0, kN)) w.frame0_N_ = r.read<std::uint32_t>(0, kN, 1, 1)[0];
  for (const char* name : {kDimensions, kTypes, kTypeShapes, kTypeId, kDiameter, kOrientation,
                           kVelocity, kAngmom, kImage})
    if (const Chunk* c = r.find(0, name))
      w.frame0_[name] = EncodedChunk{c->type, c->N, c->M, r.read_bytes(*c)};
  for (const auto& name : r.names_with_prefix(kLogPrefix))
    if (r.has(0, name)) w.frame0_logs_.push_back(name.substr(kLogPrefix.size()));
  return w;
}

void HoomdWriter::write_frame(const HoomdFrame& f) {
  const auto& path = file_.path();
  const std::uint64_t N = f.N;
  const bool first = nframes() == 0;

  // Validate everything before the first byte goes out.
  if (f.dimensions != 2 && f.dimensions != 3)
    bad_frame(path, fmt::format("dimensions = {}, must be 2 or 3", int{f.dimensions}));
  check_size(path, "position", f.position.size(), N, 3, false);
  check_size(path, "orientation", f.orientation.size(), N, 4, true);
  check_size(path, "type_id", f.type_id.size(), N, 1, true);
  check_size(path, "diameter", f.diameter.size(), N, 1, true);
  check_size(path, "velocity", f.velocity.size(), N, 3, true);
  check_size(path, "angmom", f.angmom.size(), N, 4, true);
  check_size(path, "image", f.image.size(), N, 3, true);
  for (const auto& t : f.types)
    if (t.empty() || t.find('\0') != std::string::npos)
      bad_frame(path, fmt::format("type name '{}' is empty or contains a 0 byte", t));
  // Types in force: this frame's, else frame 0's (a reader falls back to them), else {"A"}.
  std::uint64_t NT = f.types.size();
  if (NT == 0) {
    const auto it = frame0_.find(kTypes);
    NT = (!first && it != frame0_.end()) ? it->second.N : 1;
  }
  for (std::uint32_t id : f.type_id)
    if (id >= NT) bad_frame(path, fmt::format("type_id {} but there are {} types", id, NT));
  if (!f.type_shapes.empty() && f.type_shapes.size() != NT)
    bad_frame(path, fmt::format("{} type_shapes for {} types", f.type_shapes.size(), NT));
  for (const auto& s : f.type_shapes) {
    const auto j = nlohmann::json::parse(s, nullptr, false);
    if (j.is_discarded() || !j.is_object() || s.find('\0') != std::string::npos)
      bad_frame(path, fmt::format("type_shapes entry '{}' is not a JSON object", s));
  }
  for (const auto& [key, a] : f.log) {
    if (key.empty()) bad_frame(path, "empty log key");
    if (a.cols == 0 || a.values.size() != a.rows * a.cols)
      bad_frame(path, fmt::format("log '{}' has {} values for {} x {}", key, a.values.size(),
                                  a.rows, a.cols));
    if (!first && std::find(frame0_logs_.begin(), frame0_logs_.end(), key) == frame0_logs_.end())
      bad_frame(path, fmt::format("log '{}' is not in frame 0 (the hoomd schema requires every "
                                  "log chunk to be present in frame 0)", key));
  }

  // What this frame holds, in schema order.
  std::vector<Planned> plan;
  plan.push_back({kStep, encode(&f.step, 1, 1), Fallback::none, {}});
  plan.push_back({kDimensions, encode(&f.dimensions, 1, 1), Fallback::global,
                  encode<std::uint8_t>(std::vector<std::uint8_t>{3}, 1)});
  plan.push_back({kBox, encode(f.box.data(), 6, 1), Fallback::none, {}});
  plan.push_back({kN, encode(&f.N, 1, 1), Fallback::none, {}});
  if (!f.types.empty())
    plan.push_back({kTypes, encode_strings(f.types), Fallback::global, encode_strings({"A"})});
  if (!f.type_shapes.empty())
    plan.push_back({kTypeShapes, encode_strings(f.type_shapes), Fallback::global, {}});
  if (!f.type_id.empty())
    plan.push_back({kTypeId, encode(f.type_id, 1), Fallback::per_particle,
                    repeated<std::uint32_t>(N, {0})});
  if (!f.diameter.empty())
    plan.push_back({kDiameter, encode(f.diameter, 1), Fallback::per_particle, repeated<float>(N, {1})});
  if (N > 0) plan.push_back({kPosition, encode(f.position, 3), Fallback::none, {}});
  if (!f.orientation.empty())
    plan.push_back({kOrientation, encode(f.orientation, 4), Fallback::per_particle,
                    repeated<float>(N, {1, 0, 0, 0})});
  if (!f.velocity.empty())
    plan.push_back({kVelocity, encode(f.velocity, 3), Fallback::per_particle,
                    repeated<float>(N, {0, 0, 0})});
  if (!f.angmom.empty())
    plan.push_back({kAngmom, encode(f.angmom, 4), Fallback::per_particle,
                    repeated<float>(N, {0, 0, 0, 0})});
  if (!f.image.empty())
    plan.push_back({kImage, encode(f.image, 3), Fallback::per_particle,
                    repeated<std::int32_t>(N, {0, 0, 0})});
  for (const auto& [key, a] : f.log)
    plan.push_back({std::string(kLogPrefix) + key, encode(a.values.data(), a.rows, a.cols),
                    Fallback::none, {}});

  // Leave out what a reader reconstructs exactly: frame 0's chunk or the schema default.
  for (const Planned& p : plan) {
    if (p.fallback != Fallback::none) {
      const EncodedChunk* stand_in = p.schema_default ? &*p.schema_default : nullptr;
      if (!first) {
        const auto it = frame0_.find(p.name);
        if (it != frame0_.end() && (p.fallback == Fallback::global || N == frame0_N_))
          stand_in = &it->second;
      }
      if (stand_in != nullptr && *stand_in == p.chunk) continue;
    }
    file_.write_chunk(p.name, p.chunk.type, p.chunk.N, p.chunk.M, p.chunk.bytes.data());
    if (first && p.fallback != Fallback::none) frame0_[p.name] = p.chunk;
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

void write_frame_atomic(const std::filesystem::path& path, const HoomdFrame& frame) {
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  try {
    HoomdWriter w = HoomdWriter::create(tmp);
    w.write_frame(frame);
    w.sync();
    w.close();
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec)
      throw std::runtime_error(fmt::format("{}: cannot rename {} over it: {}", path.string(),
                                           tmp.string(), ec.message()));
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
  sync_directory(path);
}

}  // namespace hb::gsd
