// .oni record walking and the cropping-property repair (see openni2_source.hpp for why). The layout is
// OpenNI's file format: a 24-byte header ("NI10", version, max timestamp, max node id), then records of
// a packed 28-byte header {magic "NIR\0", type, node id, fields size (header included), payload size,
// undo position} followed by fields and payload. No OpenNI types are needed to read it.

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "projbot/alignment/openni2_source.hpp"

namespace projbot::alignment {
namespace {

constexpr std::size_t kFileHeaderBytes = 24;
constexpr std::size_t kRecordHeaderBytes = 28;
constexpr std::uint32_t kMagic = 0x0052494E;  // "NIR\0"
enum RecordType : std::uint32_t {
  kIntProperty = 0x03,
  kRealProperty = 0x04,
  kStringProperty = 0x05,
  kGeneralProperty = 0x06,
  kStateReady = 0x09,
  kEnd = 0x0B,
  kNodeAdded = 0x0D,
  kSeekTable = 0x0E,
};
constexpr std::size_t kSeekEntryBytes = 20;  // {u64 timestamp, u32 configuration id, u64 file position}
constexpr const char kCroppingName[] = "xnCropping";
constexpr std::size_t kCroppingValueBytes = 12;  // XnCropping {XnBool enabled; 4 x XnUInt16}: all zero = off

template <typename T>
T get(const std::vector<std::uint8_t>& bytes, std::size_t at) {
  T value;
  std::memcpy(&value, bytes.data() + at, sizeof(T));
  return value;
}

template <typename T>
void put(std::vector<std::uint8_t>& bytes, std::size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof(T));
}

struct Record {
  std::size_t at = 0;
  std::uint32_t type = 0, node = 0, fields = 0, payload = 0;
  std::string name;  // node name or property name
};

std::vector<std::uint8_t> read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw AlignmentError(path.string() + ": cannot open the .oni recording");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Reads `n` bytes at offset `at` of a recording of `size` bytes into `out`; the walker checks bounds.
using ReadAt = std::function<void(std::size_t at, void* out, std::size_t n)>;

// Every record's header and name, without the frames: a recording is walked from its file by seeking,
// or from bytes already in memory.
std::vector<Record> walk(const ReadAt& read, std::size_t size, const std::filesystem::path& path) {
  const auto bad = [&](std::size_t at, const std::string& what) {
    return AlignmentError(path.string() + ": not a readable .oni recording at byte " + std::to_string(at) + ": " + what);
  };
  char identity[4] = {};
  if (size >= kFileHeaderBytes) read(0, identity, sizeof identity);
  if (size < kFileHeaderBytes || std::memcmp(identity, "NI10", 4) != 0) throw bad(0, "no NI10 header");
  std::vector<Record> records;
  std::size_t at = kFileHeaderBytes;
  for (;;) {
    if (at + kRecordHeaderBytes > size) throw bad(at, "the file ends inside a record (no end record)");
    std::uint32_t header[5];  // magic, type, node id, fields size, payload size (the undo position follows)
    read(at, header, sizeof header);
    Record r;
    r.at = at;
    if (header[0] != kMagic) throw bad(at, "record magic is not NIR");
    r.type = header[1];
    r.node = header[2];
    r.fields = header[3];
    r.payload = header[4];
    if (r.fields < kRecordHeaderBytes || at + r.fields + r.payload > size) throw bad(at, "record sizes run past the file");
    const bool named = r.type == kNodeAdded || (r.type >= kIntProperty && r.type <= kGeneralProperty);
    if (named && r.fields >= kRecordHeaderBytes + 4) {
      std::uint32_t length = 0;
      read(at + kRecordHeaderBytes, &length, sizeof length);
      if (length == 0 || kRecordHeaderBytes + 4 + length > r.fields) throw bad(at, "name runs past its record");
      r.name.resize(length - 1);
      read(at + kRecordHeaderBytes + 4, r.name.data(), length - 1);
    }
    records.push_back(r);
    if (r.type == kEnd) return records;
    at += r.fields + r.payload;
  }
}

std::vector<Record> walk(const std::vector<std::uint8_t>& bytes, const std::filesystem::path& path) {
  return walk([&](std::size_t at, void* out, std::size_t n) { std::memcpy(out, bytes.data() + at, n); }, bytes.size(), path);
}

}  // namespace

bool oni_declares_cropping(const std::filesystem::path& recording) {
  // Recordings can be large: seek from record to record instead of reading the frames.
  std::ifstream in(recording, std::ios::binary);
  if (!in) throw AlignmentError(recording.string() + ": cannot open the .oni recording");
  const ReadAt read = [&](std::size_t at, void* out, std::size_t n) {
    in.seekg(static_cast<std::streamoff>(at));
    in.read(static_cast<char*>(out), static_cast<std::streamsize>(n));
    if (!in) throw AlignmentError(recording.string() + ": cannot read byte " + std::to_string(at) + " of the .oni recording");
  };
  for (const Record& r : walk(read, std::filesystem::file_size(recording), recording))
    if (r.type == kGeneralProperty && r.name == kCroppingName) return true;
  return false;
}

bool add_oni_cropping_property(const std::filesystem::path& recording) {
  std::vector<std::uint8_t> bytes = read_all(recording);
  const std::vector<Record> records = walk(bytes, recording);
  std::vector<std::uint32_t> nodes, cropped;
  for (const Record& r : records) {
    if (r.type == kNodeAdded) nodes.push_back(r.node);
    if (r.type == kGeneralProperty && r.name == kCroppingName) cropped.push_back(r.node);
  }
  bool changed = false;
  // Insert from the back so that earlier insertion points stay valid; each insertion shifts every file
  // position stored after it: undo positions, the node's seek-table position and the seek-table entries.
  for (auto it = records.rbegin(); it != records.rend(); ++it) {
    const Record& ready = *it;
    if (ready.type != kStateReady || std::find(cropped.begin(), cropped.end(), ready.node) != cropped.end()) continue;
    if (std::find(nodes.begin(), nodes.end(), ready.node) == nodes.end()) continue;
    std::vector<std::uint8_t> record(kRecordHeaderBytes);
    const auto append32 = [&](std::uint32_t v) {
      record.resize(record.size() + 4);
      put(record, record.size() - 4, v);
    };
    append32(sizeof(kCroppingName));
    record.insert(record.end(), kCroppingName, kCroppingName + sizeof(kCroppingName));
    append32(kCroppingValueBytes);
    record.resize(record.size() + kCroppingValueBytes, 0);
    put<std::uint32_t>(record, 0, kMagic);
    put<std::uint32_t>(record, 4, kGeneralProperty);
    put<std::uint32_t>(record, 8, ready.node);
    put<std::uint32_t>(record, 12, static_cast<std::uint32_t>(record.size()));
    put<std::uint32_t>(record, 16, 0);
    put<std::uint64_t>(record, 20, 0);
    const std::uint64_t insert_at = ready.at, delta = record.size();
    const auto shift = [&](std::size_t field) {
      const auto position = get<std::uint64_t>(bytes, field);
      if (position >= insert_at && position != UINT64_MAX) put<std::uint64_t>(bytes, field, position + delta);
    };
    for (const Record& r : walk(bytes, recording)) {
      shift(r.at + 20);                                      // undo position
      if (r.type == kNodeAdded) shift(r.at + r.fields - 8);  // seek-table position, the last field
      if (r.type == kSeekTable)
        for (std::size_t e = 0; e + kSeekEntryBytes <= r.payload; e += kSeekEntryBytes) shift(r.at + r.fields + e + 12);
    }
    bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(insert_at), record.begin(), record.end());
    cropped.push_back(ready.node);
    changed = true;
  }
  if (!changed) return false;
  const std::filesystem::path temporary = recording.string() + ".repair";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw AlignmentError(temporary.string() + ": cannot write the repaired recording");
  }
  std::filesystem::rename(temporary, recording);
  return true;
}

}  // namespace projbot::alignment
