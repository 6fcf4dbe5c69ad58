// GSD file layer, version 2.0: a writer and a validating reader written for hardbody.
//
// Layout (little-endian, as every GSD file):
//   header (256 bytes)   magic, index location/size, namelist location/size, versions, names
//   index block          32-byte entries {frame, N, location, M, name id, type, flags},
//                        sorted by frame, then by name id; the first entry with location 0
//                        ends the list
//   namelist block       names separated by 0 bytes, in order of first use (id = position);
//                        its size is counted in 64-byte segments
//   data chunks          raw N x M arrays, row-major (M is the fast index)
//
// Crash safety: write_chunk() only appends data after the end of the file; end_frame() then
// writes the new names, the frame's index entries and, only when a block had to move, the header.
// A process killed at any point leaves a file that reads back up to the last completed frame,
// and that can be appended to again. end_frame() hands everything to the kernel; sync() also
// waits for the disk (fdatasync), for power-loss safety.
//
// The reader checks every structure against the file size before trusting it and throws
// std::runtime_error("<path>: <problem>") for a bad magic number, an unsupported version, a
// truncated header/index/namelist, an out-of-bounds chunk, an unknown type, and so on.
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <type_traits>
#include <unordered_map>
#include <utility>
#include <vector>

namespace hb::gsd {

// Element types, with the GSD type ids.
enum class Type : std::uint8_t {
  uint8 = 1,
  uint16 = 2,
  uint32 = 3,
  uint64 = 4,
  int8 = 5,
  int16 = 6,
  int32 = 7,
  int64 = 8,
  float32 = 9,
  float64 = 10,
  character = 11,  // UTF-8 text; added in file layer 2.1 (read only: we write 2.0 files)
};

std::size_t type_size(Type t);        // bytes per element; 0 for an unknown id
std::string_view type_name(Type t);   // "float32", ...; "unknown" for an unknown id

template <class T>
constexpr Type type_of() {
  if constexpr (std::is_same_v<T, std::uint8_t>) return Type::uint8;
  else if constexpr (std::is_same_v<T, std::uint16_t>) return Type::uint16;
  else if constexpr (std::is_same_v<T, std::uint32_t>) return Type::uint32;
  else if constexpr (std::is_same_v<T, std::uint64_t>) return Type::uint64;
  else if constexpr (std::is_same_v<T, std::int8_t>) return Type::int8;
  else if constexpr (std::is_same_v<T, std::int16_t>) return Type::int16;
  else if constexpr (std::is_same_v<T, std::int32_t>) return Type::int32;
  else if constexpr (std::is_same_v<T, std::int64_t>) return Type::int64;
  else if constexpr (std::is_same_v<T, float>) return Type::float32;
  else if constexpr (std::is_same_v<T, double>) return Type::float64;
  else static_assert(sizeof(T) == 0, "no GSD type for this C++ type");
}

// Versions are stored as 0xaaaabbbb = aaaa.bbbb.
struct Version {
  std::uint32_t major = 0;
  std::uint32_t minor = 0;
  friend bool operator==(const Version&, const Version&) = default;
};

inline constexpr Version kFileLayerVersion{2, 0};

// One index entry: where a named N x M chunk of one frame lives.
struct Chunk {
  std::uint64_t frame = 0;
  std::uint64_t N = 0;
  std::uint64_t location = 0;
  std::uint32_t M = 0;
  std::uint16_t id = 0;  // name id
  Type type = Type::uint8;
  std::uint64_t bytes() const { return N * M * type_size(type); }
};

// An N x M array read from a file.
template <class T>
struct Array {
  std::uint64_t N = 0;
  std::uint32_t M = 0;
  std::vector<T> data;  // N * M values, row-major
};

namespace detail {
// Name -> id map that looks up string_views without building a std::string.
struct NameHash {
  using is_transparent = void;
  std::size_t operator()(std::string_view s) const { return std::hash<std::string_view>{}(s); }
};
using NameIds = std::unordered_map<std::string, std::uint16_t, NameHash, std::equal_to<>>;

// An owned POSIX file descriptor: closed on destruction, moved by value.
class Fd {
 public:
  Fd() = default;
  explicit Fd(int fd) : fd_(fd) {}
  ~Fd() { reset(); }
  Fd(Fd&& o) noexcept : fd_(std::exchange(o.fd_, -1)) {}
  Fd& operator=(Fd&& o) noexcept {
    if (this != &o) {
      reset();
      fd_ = std::exchange(o.fd_, -1);
    }
    return *this;
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }
  bool open() const { return fd_ >= 0; }
  int release() { return std::exchange(fd_, -1); }
  void reset() noexcept;

 private:
  int fd_ = -1;
};
}  // namespace detail

// Read-only view of a GSD file. The header, namelist and index are read and validated on
// construction; chunk data is read on demand. Move-only (owns a file descriptor).
class Reader {
 public:
  explicit Reader(const std::filesystem::path& path);

  const std::filesystem::path& path() const { return path_; }
  std::uint64_t nframes() const { return nframes_; }
  const std::string& application() const { return application_; }
  const std::string& schema() const { return schema_; }
  Version schema_version() const { return schema_version_; }
  Version file_version() const { return file_version_; }

  // All names in the namelist (in id order), and those starting with prefix.
  const std::vector<std::string>& names() const { return names_; }
  std::vector<std::string> names_with_prefix(std::string_view prefix) const;

  // The chunk `name` of `frame`, or nullptr when the frame has no such chunk.
  const Chunk* find(std::uint64_t frame, std::string_view name) const;
  bool has(std::uint64_t frame, std::string_view name) const { return find(frame, name) != nullptr; }

  // Data of a chunk as raw bytes (size chunk.bytes()).
  std::vector<std::byte> read_bytes(const Chunk& chunk) const;

  // Typed reads; throw std::runtime_error naming file, frame and chunk when the chunk is
  // missing, has another type, or (second form) another shape.
  template <class T>
  Array<T> read(std::uint64_t frame, std::string_view name) const {
    const Chunk& c = require(frame, name, type_of<T>());
    Array<T> out{c.N, c.M, std::vector<T>(static_cast<std::size_t>(c.N) * c.M)};
    read_into(c, out.data.data());
    return out;
  }
  template <class T>
  std::vector<T> read(std::uint64_t frame, std::string_view name, std::uint64_t N,
                      std::uint32_t M) const {
    const Chunk& c = require(frame, name, type_of<T>());
    check_shape(c, name, N, M);
    std::vector<T> out(static_cast<std::size_t>(c.N) * c.M);
    read_into(c, out.data());
    return out;
  }

 private:
  const Chunk& require(std::uint64_t frame, std::string_view name, Type type) const;
  void check_shape(const Chunk& c, std::string_view name, std::uint64_t N, std::uint32_t M) const;
  void read_into(const Chunk& c, void* out) const;

  friend class Writer;

  std::filesystem::path path_;
  detail::Fd fd_;
  std::uint64_t file_size_ = 0;
  std::string application_;
  std::string schema_;
  Version schema_version_;
  Version file_version_;
  std::uint64_t index_location_ = 0;
  std::uint64_t index_allocated_ = 0;     // entries
  std::uint64_t namelist_location_ = 0;
  std::uint64_t namelist_allocated_ = 0;  // 64-byte segments
  std::uint64_t namelist_used_ = 0;       // bytes, including terminators
  std::vector<std::string> names_;
  detail::NameIds ids_;
  std::vector<Chunk> index_;              // used entries only
  std::uint64_t nframes_ = 0;
};

// Fills rows [first, first + count) of an N x M chunk: count * M * type_size bytes at `out`.
using RowFill = std::function<void(std::uint64_t first, std::uint64_t count, std::byte* out)>;

// Writes frames to a new file or appends to an existing one. Move-only. Destroying a writer with
// an unfinished frame drops that frame (its data stays in the file, unindexed and harmless).
//
// Memory: chunk data goes to the file through one buffer of buffer_size() bytes (8 MiB by
// default; larger only for a single row that does not fit), never a copy of the whole frame.
class Writer {
 public:
  // Create (or truncate) `path`. The schema version is the caller's (HOOMD schema: 1.4).
  static Writer create(const std::filesystem::path& path, std::string_view application,
                       std::string_view schema, Version schema_version);
  // Open an existing GSD 2.x file and continue after its last complete frame. If `schema` is
  // not empty the file's schema must match.
  static Writer append(const std::filesystem::path& path, std::string_view schema = {});

  // Add an N x M chunk (row-major, N*M*type_size(type) bytes at data) to the current frame.
  // Throws std::invalid_argument for M == 0, an empty or repeated name, more than 65535 names,
  // or the character type; std::runtime_error on I/O failure.
  // Returns the file offset of the chunk's data.
  std::uint64_t write_chunk(std::string_view name, Type type, std::uint64_t N, std::uint32_t M,
                            const void* data);
  // The same, with the rows produced on demand by `fill`, a buffer's worth at a time. An I/O
  // failure (or an exception from fill) drops the whole current frame.
  std::uint64_t write_chunk(std::string_view name, Type type, std::uint64_t N, std::uint32_t M,
                            const RowFill& fill);
  template <class T>
  void write_chunk(std::string_view name, std::uint64_t N, std::uint32_t M, std::span<const T> data) {
    check_count(name, N, M, data.size());
    write_chunk(name, type_of<T>(), N, M, static_cast<const void*>(data.data()));
  }
  template <class T>
  void write_chunk(std::string_view name, std::uint64_t N, std::uint32_t M, const std::vector<T>& data) {
    write_chunk(name, N, M, std::span<const T>(data));
  }

  // Commit the current frame: after it returns the frame survives a kill of the process.
  void end_frame();
  // Wait until everything committed so far is on the disk.
  void sync();
  // end_frame() is not implied: an unfinished frame is dropped. Further calls throw.
  void close();

  const std::filesystem::path& path() const { return path_; }
  std::uint64_t frame() const { return frame_; }  // index of the frame being written

  // Bytes of chunk data gathered before one write (at least 1). Tests use tiny buffers.
  void set_buffer_size(std::size_t bytes);
  std::size_t buffer_size() const { return buffer_limit_; }
  // Read n bytes of chunk data written earlier (at a location write_chunk returned).
  void read_back(std::uint64_t location, std::size_t n, void* out);

 private:
  Writer() = default;
  std::uint64_t begin_chunk(std::string_view name, Type type, std::uint64_t N, std::uint32_t M,
                            bool has_data, std::uint64_t& bytes);
  void reserve_buffer(std::size_t row);
  void drop_frame();
  void check_count(std::string_view name, std::uint64_t N, std::uint32_t M, std::size_t n) const;
  void check_open() const;
  void flush_buffer();
  void pwrite_all(const void* data, std::size_t n, std::uint64_t offset, std::string_view what);
  std::uint64_t allocate(std::uint64_t bytes);  // space at the end of the file
  void write_header();

  std::filesystem::path path_;
  detail::Fd fd_;
  std::string application_;
  std::string schema_;
  Version schema_version_;
  std::uint64_t file_end_ = 0;             // where the next byte goes
  std::uint64_t index_location_ = 0;
  std::uint64_t index_allocated_ = 0;      // entries
  std::uint64_t index_used_ = 0;
  std::uint64_t namelist_location_ = 0;
  std::uint64_t namelist_allocated_ = 0;   // 64-byte segments
  std::uint64_t namelist_written_ = 0;     // bytes of names already in the file
  std::vector<std::string> names_;
  detail::NameIds ids_;
  std::size_t names_committed_ = 0;        // names_[0, names_committed_) are in the file
  std::vector<Chunk> pending_;             // entries of the current frame
  std::vector<std::byte> buffer_;          // chunk data not yet written
  std::uint64_t buffer_location_ = 0;      // file offset of buffer_[0]
  std::size_t buffer_limit_ = std::size_t{8} << 20;
  std::uint64_t frame_ = 0;
};

}  // namespace hb::gsd
