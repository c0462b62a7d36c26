#include "projbot/config/ply_body.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "projbot/config/stop_request.hpp"

namespace projbot::config {

namespace {

struct Property {
  std::string name;
  int size = 0;        ///< bytes of a scalar, or of a list's items
  int count_size = 0;  ///< bytes of a list's count; 0 for a scalar
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

int type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

struct Header {
  std::string format;
  std::vector<Element> elements;
  std::uint64_t body = 0;  ///< the first byte after end_header's line
};

Header read_header(std::ifstream& in, const std::string& file) {
  Header h;
  std::string line;
  int number = 0;
  const auto fail = [&](const std::string& why) { throw PlyError(file + ":" + std::to_string(number) + ": PLY header: " + why); };
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "end_header") {
      const std::streamoff at = in.eof() ? -1 : static_cast<std::streamoff>(in.tellg());
      h.body = at < 0 ? UINT64_MAX : static_cast<std::uint64_t>(at);  // UINT64_MAX: the file ends with the header
      return h;
    }
    if (number > 10000) fail("no end_header in the first 10000 lines");
    if (key != "ply" && key != "format" && key != "comment" && key != "obj_info" && key != "element" && key != "property")
      fail("'" + line + "' is no PLY header line (ply, format, comment, obj_info, element, property, end_header)");
    if (key == "format") words >> h.format;
    if (key == "element") {
      Element e;
      long long count = -1;
      if (!(words >> e.name >> count) || count < 0) fail("'" + line + "' is not 'element NAME COUNT'");
      e.count = static_cast<std::uint64_t>(count);
      h.elements.push_back(e);
    }
    if (key == "property") {
      if (h.elements.empty()) fail("a property before any element");
      std::string type, count_type, item_type;
      words >> type;
      Property p;
      if (type == "list") {
        words >> count_type >> item_type;
        p.count_size = type_size(count_type);
        p.size = type_size(item_type);
        if (p.count_size == 0 || p.size == 0) fail("'" + line + "' has an unknown type");
      } else if ((p.size = type_size(type)) == 0) {
        fail("'" + line + "' has an unknown type");
      }
      words >> p.name;
      h.elements.back().properties.push_back(p);
    }
  }
  throw PlyError(file + ": PLY header: no end_header");
}

std::uint64_t list_count(const char* bytes, int size, bool big_endian) {
  std::uint64_t v = 0;
  for (int i = 0; i < size; ++i) {
    const auto b = static_cast<std::uint8_t>(bytes[big_endian ? i : size - 1 - i]);
    v = (v << 8) | b;
  }
  return v;
}

// The bytes the binary body takes, walking lists; stops early (returns more than `size`) once past it.
std::uint64_t binary_body_bytes(std::ifstream& in, const Header& h, std::uint64_t size, const std::string& file) {
  const bool big = h.format == "binary_big_endian";
  std::uint64_t at = h.body;
  for (const Element& e : h.elements) {
    bool lists = false;
    std::uint64_t fixed = 0;
    for (const Property& p : e.properties) {
      lists |= p.count_size > 0;
      fixed += static_cast<std::uint64_t>(p.count_size > 0 ? 0 : p.size);
    }
    if (!lists) {
      if (fixed != 0 && e.count > (size + 1) / fixed) return size + 1;
      at += e.count * fixed;
      continue;
    }
    in.clear();
    in.seekg(static_cast<std::streamoff>(at));  // then read on in order: a seek per list emptied the buffer each time
    for (std::uint64_t i = 0; i < e.count && at <= size; ++i) {
      if (i % kStopCheckEvery == 0) stop_if_requested("checking the body of " + file);
      for (const Property& p : e.properties) {
        if (p.count_size == 0) {
          at += static_cast<std::uint64_t>(p.size);
          in.ignore(p.size);
          continue;
        }
        char bytes[8];
        if (!in.read(bytes, p.count_size)) return size + 1;
        const std::uint64_t n = list_count(bytes, p.count_size, big);
        at += static_cast<std::uint64_t>(p.count_size);
        if (n > size / static_cast<std::uint64_t>(p.size)) return size + 1;
        at += n * static_cast<std::uint64_t>(p.size);
        in.ignore(static_cast<std::streamsize>(n * static_cast<std::uint64_t>(p.size)));
      }
    }
  }
  return at;
}

bool has_xyz(const Element& e) {
  int found = 0;
  for (const char* axis : {"x", "y", "z"})
    found += std::count_if(e.properties.begin(), e.properties.end(),
                           [&](const Property& p) { return p.name == axis && p.count_size == 0; }) > 0;
  return found == 3;
}

}  // namespace

PlyCounts check_ply_body(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw PlyError(file + ": cannot open");
  Header h = read_header(in, file);
  std::uint64_t vertices = 0, faces = 0, total = 0;
  bool xyz = false;
  for (const Element& e : h.elements) {
    if (e.name == "vertex") vertices = e.count, xyz = has_xyz(e);
    if (e.name == "face") faces = e.count;
    total += e.count;
  }
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  h.body = std::min(h.body, size);
  if (h.format == "ascii") {
    in.clear();
    in.seekg(static_cast<std::streamoff>(h.body));
    std::uint64_t lines = 0;
    std::uint64_t read = 0;
    for (std::string line; std::getline(in, line);) {
      if (++read % kStopCheckEvery == 0) stop_if_requested("checking the body of " + file);
      if (line.find_first_not_of(" \t\r") != std::string::npos) ++lines;
    }
    if (lines != total)
      throw PlyError(file + ": the header declares " + std::to_string(total) + " elements (" + std::to_string(vertices) +
                     " vertices), the body holds " + std::to_string(lines) + " lines");
    return {vertices, faces, xyz};
  }
  if (h.format != "binary_little_endian" && h.format != "binary_big_endian")
    throw PlyError(file + ": PLY format '" + h.format + "' is none of ascii, binary_little_endian, binary_big_endian");
  const std::uint64_t end = binary_body_bytes(in, h, size, file);
  if (end != size)
    throw PlyError(file + ": the header declares " + std::to_string(vertices) + " vertices and " +
                   std::to_string(total - vertices) + " other elements, " +
                   (end > size ? "more than the file holds" : "but " + std::to_string(size - end) + " bytes follow them") +
                   " (truncated, or more data than declared)");
  return {vertices, faces, xyz};
}

}  // namespace projbot::config
