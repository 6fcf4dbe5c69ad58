// GSD file layer 2.0 writer and reader; see gsd.hpp for the layout and the guarantees.
#include "io/gsd.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstring>
#include <fmt/format.h>
#include <limits>
#include <stdexcept>

namespace hb::gsd {

static_assert(std::endian::native == std::endian::little,
              "GSD files are little-endian; this implementation stores memory images directly");

namespace {

constexpr std::uint64_t kMagic = 0x65DF65DF65DF65DFull;
constexpr std::size_t kHeaderSize = 256;
constexpr std::size_t kEntrySize = 32;
constexpr std::size_t kNameSegment = 64;          // namelist sizes are counted in 64-byte units
constexpr std::size_t kNameField = 64;            // application / schema fields
constexpr std::uint64_t kInitialIndexEntries = 128;
constexpr std::uint64_t kInitialNameSegments = 16;
constexpr std::size_t kMaxNames = 65535;          // name ids are 16-bit

// Header field offsets.
constexpr std::size_t kOffIndexLocation = 8, kOffIndexAllocated = 16, kOffNamelistLocation = 24,
                      kOffNamelistAllocated = 32, kOffSchemaVersion = 40, kOffFileVersion = 44,
                      kOffApplication = 48, kOffSchema = 112;

template <class T>
T get(const std::byte* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <class T>
void put(std::byte* p, T v) {
  std::memcpy(p, &v, sizeof v);
}

std::uint32_t pack(Version v) { return (v.major << 16) | (v.minor & 0xffffu); }
Version unpack(std::uint32_t v) { return {v >> 16, v & 0xffffu}; }

std::string fixed_string(const std::byte* p, std::size_t n) {
  const char* c = reinterpret_cast<const char*>(p);
  return std::string(c, strnlen(c, n));
}

std::string errno_text() { return std::strerror(errno); }

// Entry <-> 32 bytes: frame u64, N u64, location i64, M u32, id u16, type u8, flags u8.
void encode_entry(const Chunk& c, std::byte* p) {
  put<std::uint64_t>(p, c.frame);
  put<std::uint64_t>(p + 8, c.N);
  put<std::int64_t>(p + 16, static_cast<std::int64_t>(c.location));
  put<std::uint32_t>(p + 24, c.M);
  put<std::uint16_t>(p + 28, c.id);
  put<std::uint8_t>(p + 30, static_cast<std::uint8_t>(c.type));
  put<std::uint8_t>(p + 31, 0);
}

// Read exactly n bytes at offset; false on a short read.
bool pread_all(int fd, void* out, std::size_t n, std::uint64_t offset) {
  auto* p = static_cast<char*>(out);
  while (n > 0) {
    const ssize_t r = ::pread(fd, p, n, static_cast<off_t>(offset));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) return false;
    p += r;
    n -= static_cast<std::size_t>(r);
    offset += static_cast<std::uint64_t>(r);
  }
  return true;
}

// a * b + c without wrapping; false on overflow.
bool mul_add(std::uint64_t a, std::uint64_t b, std::uint64_t c, std::uint64_t& out) {
  std::uint64_t prod;
  if (__builtin_mul_overflow(a, b, &prod)) return false;
  return !__builtin_add_overflow(prod, c, &out);
}

}  // namespace

std::size_t type_size(Type t) {
  switch (t) {
    case Type::uint8: case Type::int8: case Type::character: return 1;
    case Type::uint16: case Type::int16: return 2;
    case Type::uint32: case Type::int32: case Type::float32: return 4;
    case Type::uint64: case Type::int64: case Type::float64: return 8;
  }
  return 0;
}

std::string_view type_name(Type t) {
  switch (t) {
    case Type::uint8: return "uint8";
    case Type::uint16: return "uint16";
    case Type::uint32: return "uint32";
    case Type::uint64: return "uint64";
    case Type::int8: return "int8";
    case Type::int16: return "int16";
    case Type::int32: return "int32";
    case Type::int64: return "int64";
    case Type::float32: return "float32";
    case Type::float64: return "float64";
    case Type::character: return "character";
  }
  return "unknown";
}

void detail::Fd::reset() noexcept {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

// ---------------------------------------------------------------------------------------------
// Reader

Reader::Reader(const std::filesystem::path& path) : path_(path) {
  const std::string p = path.string();
  auto fail = [&](const std::string& what) -> std::runtime_error {
    fd_.reset();
    return std::runtime_error(fmt::format("{}: {}", p, what));
  };

  fd_ = detail::Fd(::open(p.c_str(), O_RDONLY | O_CLOEXEC));
  if (!fd_.open()) throw fail(fmt::format("cannot open GSD file: {}", errno_text()));
  struct stat st {};
  if (::fstat(fd_.get(), &st) != 0) throw fail(fmt::format("cannot stat: {}", errno_text()));
  file_size_ = static_cast<std::uint64_t>(st.st_size);

  // Header.
  std::byte h[kHeaderSize];
  if (file_size_ < kHeaderSize || !pread_all(fd_.get(), h, kHeaderSize, 0))
    throw fail(fmt::format("truncated header: the file has {} bytes, a GSD header needs {}",
                           file_size_, kHeaderSize));
  const auto magic = get<std::uint64_t>(h);
  if (magic != kMagic)
    throw fail(fmt::format("bad magic number {:#018x}: not a GSD file", magic));
  file_version_ = unpack(get<std::uint32_t>(h + kOffFileVersion));
  const bool v1 = file_version_ == Version{1, 0};
  if (!v1 && !(file_version_.major == 2 && file_version_.minor <= 1))
    throw fail(fmt::format("unknown GSD file layer version {}.{} (this reader knows 1.0, 2.0, 2.1)",
                           file_version_.major, file_version_.minor));
  schema_version_ = unpack(get<std::uint32_t>(h + kOffSchemaVersion));
  application_ = fixed_string(h + kOffApplication, kNameField);
  schema_ = fixed_string(h + kOffSchema, kNameField);
  index_location_ = get<std::uint64_t>(h + kOffIndexLocation);
  index_allocated_ = get<std::uint64_t>(h + kOffIndexAllocated);
  namelist_location_ = get<std::uint64_t>(h + kOffNamelistLocation);
  namelist_allocated_ = get<std::uint64_t>(h + kOffNamelistAllocated);

  // Namelist.
  std::uint64_t namelist_end = 0;
  if (namelist_location_ < kHeaderSize ||
      !mul_add(namelist_allocated_, kNameSegment, namelist_location_, namelist_end) ||
      namelist_end > file_size_)
    throw fail(fmt::format(
        "truncated namelist: block at offset {} with {} x 64 bytes does not fit in the file "
        "({} bytes)", namelist_location_, namelist_allocated_, file_size_));
  std::vector<char> nl(namelist_allocated_ * kNameSegment);
  if (!pread_all(fd_.get(), nl.data(), nl.size(), namelist_location_))
    throw fail("cannot read the namelist");
  for (std::size_t pos = 0; pos < nl.size();) {
    const std::size_t limit = v1 ? std::min(nl.size(), pos + kNameSegment) : nl.size();
    const char* s = nl.data() + pos;
    const std::size_t len = strnlen(s, limit - pos);
    if (len == 0) break;  // the first empty name ends the list
    if (pos + len == limit)
      throw fail(fmt::format("corrupt namelist: name {} is not 0-terminated", names_.size()));
    if (names_.size() == kMaxNames) throw fail("corrupt namelist: more than 65535 names");
    std::string name(s, len);
    if (!ids_.emplace(name, static_cast<std::uint16_t>(names_.size())).second)
      throw fail(fmt::format("corrupt namelist: name '{}' appears twice", name));
    names_.push_back(std::move(name));
    pos = v1 ? pos + kNameSegment : pos + len + 1;
    namelist_used_ = pos;
  }

  // Index.
  std::uint64_t index_end = 0;
  if (index_location_ < kHeaderSize ||
      !mul_add(index_allocated_, kEntrySize, index_location_, index_end) || index_end > file_size_)
    throw fail(fmt::format(
        "truncated index: block at offset {} with {} entries of 32 bytes does not fit in the file "
        "({} bytes)", index_location_, index_allocated_, file_size_));
  std::vector<std::byte> raw(index_allocated_ * kEntrySize);
  if (!pread_all(fd_.get(), raw.data(), raw.size(), index_location_))
    throw fail("cannot read the index");
  for (std::uint64_t i = 0; i < index_allocated_; ++i) {
    const std::byte* e = raw.data() + i * kEntrySize;
    const auto location = get<std::int64_t>(e + 16);
    if (location == 0) break;  // end of the used entries
    Chunk c;
    c.frame = get<std::uint64_t>(e);
    c.N = get<std::uint64_t>(e + 8);
    c.location = static_cast<std::uint64_t>(location);
    c.M = get<std::uint32_t>(e + 24);
    c.id = get<std::uint16_t>(e + 28);
    c.type = static_cast<Type>(get<std::uint8_t>(e + 30));
    const auto flags = get<std::uint8_t>(e + 31);
    const std::string where = fmt::format("corrupt index entry {}", i);
    if (type_size(c.type) == 0)
      throw fail(fmt::format("{}: unknown type id {}", where, static_cast<int>(c.type)));
    if (c.M == 0) throw fail(fmt::format("{}: M = 0", where));
    if (flags != 0) throw fail(fmt::format("{}: unknown flags {}", where, flags));
    if (c.id >= names_.size())
      throw fail(fmt::format("{}: name id {} but the namelist has {} names", where, c.id,
                             names_.size()));
    if (c.frame >= index_allocated_)
      throw fail(fmt::format("{}: frame {} is impossible with {} index entries", where, c.frame,
                             index_allocated_));
    if (!index_.empty() && c.frame < index_.back().frame)
      throw fail(fmt::format("{}: frame {} follows frame {} (index not sorted)", where, c.frame,
                             index_.back().frame));
    std::uint64_t end = 0;
    if (location < static_cast<std::int64_t>(kHeaderSize) ||
        !mul_add(c.N, std::uint64_t{c.M} * type_size(c.type), c.location, end) ||
        end > file_size_)
      throw fail(fmt::format(
          "chunk '{}' of frame {} ({} x {} {} at offset {}) is out of bounds: the file has {} "
          "bytes (truncated file?)", names_[c.id], c.frame, c.N, c.M, type_name(c.type),
          location, file_size_));
    index_.push_back(c);
  }
  nframes_ = index_.empty() ? 0 : index_.back().frame + 1;
}

std::vector<std::string> Reader::names_with_prefix(std::string_view prefix) const {
  std::vector<std::string> out;
  for (const auto& n : names_)
    if (n.starts_with(prefix)) out.push_back(n);
  return out;
}

const Chunk* Reader::find(std::uint64_t frame, std::string_view name) const {
  const auto it = ids_.find(name);
  if (it == ids_.end()) return nullptr;
  auto c = std::lower_bound(index_.begin(), index_.end(), frame,
                            [](const Chunk& a, std::uint64_t f) { return a.frame < f; });
  for (; c != index_.end() && c->frame == frame; ++c)
    if (c->id == it->second) return &*c;
  return nullptr;
}

const Chunk& Reader::require(std::uint64_t frame, std::string_view name, Type type) const {
  const Chunk* c = find(frame, name);
  if (c == nullptr)
    throw std::runtime_error(fmt::format("{}: frame {} has no chunk '{}' ({} frames in the file)",
                                         path_.string(), frame, name, nframes_));
  if (c->type != type)
    throw std::runtime_error(fmt::format("{}: chunk '{}' of frame {} has type {}, expected {}",
                                         path_.string(), name, frame, type_name(c->type),
                                         type_name(type)));
  return *c;
}

void Reader::check_shape(const Chunk& c, std::string_view name, std::uint64_t N,
                         std::uint32_t M) const {
  if (c.N != N || c.M != M)
    throw std::runtime_error(fmt::format("{}: chunk '{}' of frame {} is {} x {}, expected {} x {}",
                                         path_.string(), name, c.frame, c.N, c.M, N, M));
}

void Reader::read_into(const Chunk& c, void* out) const {
  if (!pread_all(fd_.get(), out, c.bytes(), c.location))
    throw std::runtime_error(fmt::format("{}: cannot read chunk '{}' of frame {} at offset {}",
                                         path_.string(), names_.at(c.id), c.frame, c.location));
}

std::vector<std::byte> Reader::read_bytes(const Chunk& c) const {
  std::vector<std::byte> out(c.bytes());
  read_into(c, out.data());
  return out;
}

// ---------------------------------------------------------------------------------------------
// Writer

Writer Writer::create(const std::filesystem::path& path, std::string_view application,
                      std::string_view schema, Version schema_version) {
  if (application.size() >= kNameField || schema.size() >= kNameField)
    throw std::invalid_argument(fmt::format(
        "{}: application and schema names must be shorter than 64 bytes", path.string()));
  Writer w;
  w.path_ = path;
  w.application_ = application;
  w.schema_ = schema;
  w.schema_version_ = schema_version;
  w.fd_ = detail::Fd(::open(path.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
  if (!w.fd_.open())
    throw std::runtime_error(fmt::format("{}: cannot create GSD file: {}", path.string(),
                                         errno_text()));
  w.index_location_ = kHeaderSize;
  w.index_allocated_ = kInitialIndexEntries;
  w.namelist_location_ = w.index_location_ + kInitialIndexEntries * kEntrySize;
  w.namelist_allocated_ = kInitialNameSegments;
  w.file_end_ = w.namelist_location_ + kInitialNameSegments * kNameSegment;
  const std::vector<std::byte> zeros(w.file_end_ - kHeaderSize);
  w.pwrite_all(zeros.data(), zeros.size(), kHeaderSize, "empty index and namelist");
  w.write_header();
  return w;
}

Writer Writer::append(const std::filesystem::path& path, std::string_view schema) {
  Reader r(path);  // validates the whole file
  if (r.file_version().major != 2)
    throw std::runtime_error(fmt::format(
        "{}: cannot append to a GSD {}.{} file (only 2.x)", path.string(),
        r.file_version().major, r.file_version().minor));
  if (!schema.empty() && r.schema() != schema)
    throw std::runtime_error(fmt::format("{}: schema is '{}', expected '{}'", path.string(),
                                         r.schema(), schema));
  Writer w;
  w.path_ = path;
  w.fd_ = detail::Fd(::open(path.c_str(), O_RDWR | O_CLOEXEC));
  if (!w.fd_.open())
    throw std::runtime_error(fmt::format("{}: cannot open GSD file for appending: {}",
                                         path.string(), errno_text()));
  struct stat st {};
  if (::fstat(w.fd_.get(), &st) != 0)
    throw std::runtime_error(fmt::format("{}: cannot stat: {}", path.string(), errno_text()));
  // Data of a frame that was never committed may follow the last indexed chunk; leave it.
  w.file_end_ = static_cast<std::uint64_t>(st.st_size);
  w.application_ = r.application_;
  w.schema_ = r.schema_;
  w.schema_version_ = r.schema_version_;
  w.index_location_ = r.index_location_;
  w.index_allocated_ = r.index_allocated_;
  w.index_used_ = r.index_.size();
  w.namelist_location_ = r.namelist_location_;
  w.namelist_allocated_ = r.namelist_allocated_;
  w.namelist_written_ = r.namelist_used_;
  w.names_ = std::move(r.names_);
  w.ids_ = std::move(r.ids_);
  w.names_committed_ = w.names_.size();
  w.frame_ = r.nframes_;
  return w;
}

void Writer::check_open() const {
  if (!fd_.open())
    throw std::logic_error(fmt::format("{}: GSD writer is closed", path_.string()));
}

void Writer::check_count(std::string_view name, std::uint64_t N, std::uint32_t M,
                         std::size_t n) const {
  std::uint64_t want = 0;
  if (!mul_add(N, M, 0, want) || want != n)
    throw std::invalid_argument(fmt::format("{}: chunk '{}' declared {} x {} but has {} values",
                                            path_.string(), name, N, M, n));
}

void Writer::pwrite_all(const void* data, std::size_t n, std::uint64_t offset,
                        std::string_view what) {
  const auto* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t r = ::pwrite(fd_.get(), p, n, static_cast<off_t>(offset));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0)
      throw std::runtime_error(fmt::format("{}: cannot write {}: {}", path_.string(), what,
                                           r < 0 ? errno_text() : "no progress"));
    p += r;
    n -= static_cast<std::size_t>(r);
    offset += static_cast<std::uint64_t>(r);
  }
}

std::uint64_t Writer::allocate(std::uint64_t bytes) {
  const std::uint64_t at = file_end_;
  file_end_ += bytes;
  return at;
}

void Writer::write_header() {
  std::byte h[kHeaderSize] = {};
  put<std::uint64_t>(h, kMagic);
  put<std::uint64_t>(h + kOffIndexLocation, index_location_);
  put<std::uint64_t>(h + kOffIndexAllocated, index_allocated_);
  put<std::uint64_t>(h + kOffNamelistLocation, namelist_location_);
  put<std::uint64_t>(h + kOffNamelistAllocated, namelist_allocated_);
  put<std::uint32_t>(h + kOffSchemaVersion, pack(schema_version_));
  put<std::uint32_t>(h + kOffFileVersion, pack(kFileLayerVersion));
  std::memcpy(h + kOffApplication, application_.data(), application_.size());
  std::memcpy(h + kOffSchema, schema_.data(), schema_.size());
  pwrite_all(h, kHeaderSize, 0, "header");
}

void Writer::flush_buffer() {
  if (buffer_.empty()) return;
  pwrite_all(buffer_.data(), buffer_.size(), buffer_location_, "chunk data");
  buffer_.clear();
}

void Writer::reserve_buffer(std::size_t row) {
  const std::size_t want = std::max(buffer_limit_, row);
  if (buffer_.capacity() < want) buffer_.reserve(want);  // the only buffer; it never grows past this
}

// After a failed chunk the frame is lost (its data is never indexed); earlier frames stay intact.
void Writer::drop_frame() {
  buffer_.clear();
  pending_.clear();
}

void Writer::set_buffer_size(std::size_t bytes) {
  flush_buffer();
  buffer_limit_ = std::max<std::size_t>(bytes, 1);
  std::vector<std::byte>().swap(buffer_);  // give back a larger buffer
}

void Writer::read_back(std::uint64_t location, std::size_t n, void* out) {
  check_open();
  flush_buffer();
  if (!pread_all(fd_.get(), out, n, location))
    throw std::runtime_error(fmt::format("{}: cannot read back {} bytes at offset {}: {}",
                                         path_.string(), n, location, errno_text()));
}

// Validates a chunk, gives its name an id and its data a place at the end of the file.
std::uint64_t Writer::begin_chunk(std::string_view name, Type type, std::uint64_t N,
                                  std::uint32_t M, bool has_data, std::uint64_t& bytes) {
  check_open();
  const auto bad = [&](std::string_view why) {
    return std::invalid_argument(fmt::format("{}: cannot write chunk '{}': {}", path_.string(),
                                             name, why));
  };
  if (name.empty()) throw bad("empty name");
  if (name.find('\0') != std::string_view::npos) throw bad("name contains a 0 byte");
  if (M == 0) throw bad("M must be at least 1");
  if (type == Type::character) throw bad("the character type needs file layer 2.1");
  if (type_size(type) == 0) throw bad("unknown type");
  if (!mul_add(N, std::uint64_t{M} * type_size(type), 0, bytes)) throw bad("size overflows");
  if (N > 0 && !has_data) throw bad("no data");

  std::uint16_t id = 0;
  if (auto it = ids_.find(name); it != ids_.end()) {
    id = it->second;
    for (const Chunk& c : pending_)
      if (c.id == id) throw bad(fmt::format("already written in frame {}", frame_));
  } else {
    if (names_.size() == kMaxNames) throw bad("a GSD file holds at most 65535 names");
    id = static_cast<std::uint16_t>(names_.size());
    names_.emplace_back(name);
    ids_.emplace(names_.back(), id);
  }
  if (buffer_.empty()) buffer_location_ = file_end_;
  const std::uint64_t location = allocate(bytes);
  pending_.push_back(Chunk{frame_, N, location, M, id, type});
  return location;
}

std::uint64_t Writer::write_chunk(std::string_view name, Type type, std::uint64_t N,
                                  std::uint32_t M, const void* data) {
  std::uint64_t bytes = 0;
  const std::uint64_t location = begin_chunk(name, type, N, M, data != nullptr, bytes);
  try {
    if (bytes >= buffer_limit_) {  // straight from the caller's memory
      flush_buffer();
      pwrite_all(data, bytes, location, fmt::format("chunk '{}'", name));
    } else if (bytes > 0) {
      if (buffer_.size() + bytes > buffer_limit_) flush_buffer();
      reserve_buffer(0);
      if (buffer_.empty()) buffer_location_ = location;
      const auto* p = static_cast<const std::byte*>(data);
      buffer_.insert(buffer_.end(), p, p + bytes);
      if (buffer_.size() >= buffer_limit_) flush_buffer();
    }
  } catch (...) {
    drop_frame();
    throw;
  }
  return location;
}

std::uint64_t Writer::write_chunk(std::string_view name, Type type, std::uint64_t N,
                                  std::uint32_t M, const RowFill& fill) {
  std::uint64_t bytes = 0;
  const std::uint64_t location = begin_chunk(name, type, N, M, bool(fill), bytes);
  const std::size_t row = std::size_t{M} * type_size(type);
  try {
    reserve_buffer(row);
    for (std::uint64_t first = 0; first < N;) {
      std::size_t room = buffer_limit_ > buffer_.size() ? buffer_limit_ - buffer_.size() : 0;
      if (room < row && !buffer_.empty()) {
        flush_buffer();
        room = buffer_limit_;
      }
      if (buffer_.empty()) buffer_location_ = location + first * row;
      const std::uint64_t count = std::min<std::uint64_t>(N - first, std::max<std::size_t>(room / row, 1));
      const std::size_t at = buffer_.size();
      buffer_.resize(at + count * row);
      fill(first, count, buffer_.data() + at);
      first += count;
      if (buffer_.size() >= buffer_limit_) flush_buffer();
    }
  } catch (...) {
    drop_frame();
    throw;
  }
  return location;
}

void Writer::end_frame() {
  check_open();
  // 1. Chunk data.
  flush_buffer();
  bool header_changed = false;

  // 2. New names: appended in place, or the whole namelist moved to the end of the file.
  if (names_committed_ < names_.size()) {
    std::vector<char> fresh;
    for (std::size_t i = names_committed_; i < names_.size(); ++i) {
      fresh.insert(fresh.end(), names_[i].begin(), names_[i].end());
      fresh.push_back('\0');
    }
    const std::uint64_t capacity = namelist_allocated_ * kNameSegment;
    if (namelist_written_ + fresh.size() + 1 <= capacity) {  // keep a 0 byte as end marker
      pwrite_all(fresh.data(), fresh.size(), namelist_location_ + namelist_written_, "namelist");
    } else {
      std::uint64_t segments = namelist_allocated_;
      while (segments * kNameSegment < namelist_written_ + fresh.size() + 1) segments *= 2;
      std::vector<char> block(segments * kNameSegment, '\0');
      std::size_t pos = 0;
      for (const auto& n : names_) {
        std::memcpy(block.data() + pos, n.data(), n.size());
        pos += n.size() + 1;
      }
      const std::uint64_t at = allocate(block.size());
      pwrite_all(block.data(), block.size(), at, "namelist");
      namelist_location_ = at;
      namelist_allocated_ = segments;
      header_changed = true;
    }
    namelist_written_ += fresh.size();
    names_committed_ = names_.size();
  }

  // 3. Index entries of this frame, sorted by name id (the file layer requires it).
  std::stable_sort(pending_.begin(), pending_.end(),
                   [](const Chunk& a, const Chunk& b) { return a.id < b.id; });
  std::vector<std::byte> entries(pending_.size() * kEntrySize);
  for (std::size_t i = 0; i < pending_.size(); ++i)
    encode_entry(pending_[i], entries.data() + i * kEntrySize);
  if (index_used_ + pending_.size() <= index_allocated_) {
    pwrite_all(entries.data(), entries.size(), index_location_ + index_used_ * kEntrySize,
               "index");
  } else {
    // Copy the block to a larger one at the end; the old one stays valid until the header moves.
    std::uint64_t allocated = index_allocated_;
    while (allocated < index_used_ + pending_.size()) allocated *= 2;
    std::vector<std::byte> block(allocated * kEntrySize);
    if (!pread_all(fd_.get(), block.data(), index_used_ * kEntrySize, index_location_))
      throw std::runtime_error(fmt::format("{}: cannot read the index back", path_.string()));
    std::memcpy(block.data() + index_used_ * kEntrySize, entries.data(), entries.size());
    const std::uint64_t at = allocate(block.size());
    pwrite_all(block.data(), block.size(), at, "index");
    index_location_ = at;
    index_allocated_ = allocated;
    header_changed = true;
  }
  index_used_ += pending_.size();
  pending_.clear();

  // 4. The header last: a kill before this point leaves the old, still valid, blocks in use.
  if (header_changed) write_header();
  ++frame_;
}

void Writer::sync() {
  check_open();
  if (::fdatasync(fd_.get()) != 0)
    throw std::runtime_error(fmt::format("{}: fdatasync failed: {}", path_.string(),
                                         errno_text()));
}

void Writer::close() {
  check_open();
  pending_.clear();
  buffer_.clear();
  if (::close(fd_.release()) != 0)
    throw std::runtime_error(fmt::format("{}: close failed: {}", path_.string(), errno_text()));
}

}  // namespace hb::gsd
