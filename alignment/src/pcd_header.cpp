#include "pcd_header.hpp"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <sstream>

#include "projbot/alignment/depth.hpp"

namespace projbot::alignment::detail {

namespace {

constexpr std::size_t kMaxHeaderBytes = 64 * 1024;

struct Reader {
  const std::filesystem::path& path;
  int line = 0;
  [[noreturn]] void fail(const std::string& what) const {
    throw AlignmentError(path.string() + ": malformed PCD file" +
                         (line > 0 ? " (header line " + std::to_string(line) + ")" : "") + ": " + what);
  }
  std::uint64_t number(const std::string& word, const char* key) const {
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), v);
    if (ec != std::errc() || end != word.data() + word.size())
      fail(std::string(key) + " must be a whole number, got '" + word + "'");
    return v;
  }
};

std::vector<std::string> words_of(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// Fills one header key from its words; returns false for an unknown key.
void read_key(const Reader& r, const std::vector<std::string>& w, PcdHeader& h) {
  const std::string& key = w[0];
  const std::vector<std::string> values(w.begin() + 1, w.end());
  const auto one = [&](const char* name) {
    if (values.size() != 1) r.fail(std::string(name) + " takes one value");
    return r.number(values[0], name);
  };
  if (key == "FIELDS" || key == "COLUMNS") {
    h.fields = values;
  } else if (key == "SIZE") {
    h.sizes.clear();
    for (const auto& v : values) {
      const auto s = r.number(v, "SIZE");
      if (s != 1 && s != 2 && s != 4 && s != 8) r.fail("SIZE must be 1, 2, 4 or 8, got " + v);
      h.sizes.push_back(static_cast<int>(s));
    }
  } else if (key == "TYPE") {
    h.types.clear();
    for (const auto& v : values) {
      if (v != "I" && v != "U" && v != "F") r.fail("TYPE must be I, U or F, got '" + v + "'");
      h.types.push_back(v[0]);
    }
  } else if (key == "COUNT") {
    h.counts.clear();
    for (const auto& v : values) {
      const auto c = r.number(v, "COUNT");
      if (c < 1 || c > 4096) r.fail("COUNT must be 1 to 4096, got " + v);
      h.counts.push_back(static_cast<int>(c));
    }
  } else if (key == "WIDTH") {
    h.width = one("WIDTH");
  } else if (key == "HEIGHT") {
    h.height = one("HEIGHT");
  } else if (key == "POINTS") {
    h.points = one("POINTS");
  } else if (key == "DATA") {
    if (values.size() != 1 || (values[0] != "ascii" && values[0] != "binary" && values[0] != "binary_compressed"))
      r.fail("DATA must be ascii, binary or binary_compressed");
    h.data = values[0];
  } else if (key != "VERSION" && key != "VIEWPOINT") {
    r.fail("unknown header key '" + key + "'");
  }
}

void check_fields(const Reader& r, PcdHeader& h) {
  const std::size_t n = h.fields.size();
  if (n == 0) r.fail("no FIELDS line");
  if (h.counts.empty()) h.counts.assign(n, 1);
  if (h.sizes.size() != n || h.types.size() != n || h.counts.size() != n)
    r.fail(std::to_string(n) + " FIELDS but " + std::to_string(h.sizes.size()) + " SIZE, " + std::to_string(h.types.size()) +
           " TYPE and " + std::to_string(h.counts.size()) + " COUNT values");
  for (const char* axis : {"x", "y", "z"})
    if (std::find(h.fields.begin(), h.fields.end(), axis) == h.fields.end())
      r.fail("no '" + std::string(axis) + "' field: a point cloud needs x, y and z (FIELDS has " + std::to_string(n) + ")");
}

void check_data(const Reader& r, const PcdHeader& h, std::ifstream& in, std::uint64_t file_size) {
  const std::uint64_t left = file_size - h.data_offset;
  const std::string claim = "claims " + std::to_string(h.points) + " points";
  if (h.data == "binary") {
    if (left / h.point_bytes() < h.points)
      r.fail(claim + " of " + std::to_string(h.point_bytes()) + " bytes, but its data section has " + std::to_string(left) +
             " bytes");
  } else if (h.data == "binary_compressed") {
    std::uint32_t sizes[2] = {0, 0};
    if (left < 8 || !in.seekg(static_cast<std::streamoff>(h.data_offset)).read(reinterpret_cast<char*>(sizes), 8))
      r.fail(claim + ", but the compressed data section is missing");
    if (sizes[0] == 0 || sizes[0] > left - 8)
      r.fail(claim + ": the compressed section says " + std::to_string(sizes[0]) + " bytes, the file holds " +
             std::to_string(left - 8));
    if (sizes[1] != h.points * h.point_bytes())
      r.fail(claim + " (" + std::to_string(h.points * h.point_bytes()) + " bytes), but the compressed section unpacks to " +
             std::to_string(sizes[1]) + " bytes");
  } else {
    // ascii: every value takes at least a digit and a separator.
    std::uint64_t values = 0;
    for (const int c : h.counts) values += static_cast<std::uint64_t>(c);
    if (left / (2 * values) < h.points)
      r.fail(claim + ", but its data section of " + std::to_string(left) + " bytes cannot hold that many");
  }
}

}  // namespace

std::uint64_t PcdHeader::point_bytes() const {
  std::uint64_t b = 0;
  for (std::size_t i = 0; i < sizes.size(); ++i)
    b += static_cast<std::uint64_t>(sizes[i]) * static_cast<std::uint64_t>(counts[i]);
  return b;
}

PcdHeader check_pcd(const std::filesystem::path& path) {
  Reader r{path};
  std::ifstream in(path, std::ios::binary);
  std::error_code ec;
  const std::uint64_t file_size = std::filesystem::file_size(path, ec);
  if (!in || ec) throw AlignmentError(path.string() + ": cannot open the PCD file");
  if (file_size == 0) r.fail("the file is empty");
  PcdHeader h;
  for (std::string text; h.data.empty() && std::getline(in, text);) {
    ++r.line;
    if (static_cast<std::uint64_t>(in.tellg()) > kMaxHeaderBytes) r.fail("no DATA line in the first 64 KiB");
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (text.empty() || text[0] == '#') continue;
    if (std::any_of(text.begin(), text.end(), [](unsigned char c) { return c < 9 || c == 127; }))
      r.fail("binary bytes in the header: not a PCD file?");
    const auto words = words_of(text);
    if (!words.empty()) read_key(r, words, h);
  }
  if (h.data.empty()) r.fail("no DATA line: the header never ends");
  h.data_offset = in.eof() ? file_size : static_cast<std::uint64_t>(in.tellg());
  check_fields(r, h);
  if (h.width == 0 || h.height == 0) r.fail("WIDTH and HEIGHT must be > 0 (the cloud holds no points)");
  if (h.width > (std::uint64_t{1} << 32) / h.height) r.fail("WIDTH x HEIGHT is too large");
  if (h.points == 0) h.points = h.width * h.height;
  if (h.points != h.width * h.height)
    r.fail("POINTS " + std::to_string(h.points) + " is not WIDTH x HEIGHT = " + std::to_string(h.width * h.height));
  r.line = 0;
  check_data(r, h, in, file_size);
  return h;
}

}  // namespace projbot::alignment::detail
