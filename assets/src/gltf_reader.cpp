// The glTF reader's shared checks: accessors bounded by their buffers, components read with glTF's
// normalisation, warnings said once.

#include "gltf_reader.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <mutex>
#include <set>

namespace projbot::assets::detail {

GltfReader::View GltfReader::accessor_view(int accessor_index, const std::string& what) const {
  check_index(accessor_index, g_.accessors, what + " accessor");
  const auto& a = g_.accessors[static_cast<std::size_t>(accessor_index)];
  const std::string name = what + " (accessor " + std::to_string(accessor_index) + ")";
  if (a.sparse.isSparse) fail(name + ": sparse accessors are not supported");
  if (a.bufferView < 0) fail(name + ": has no bufferView");
  check_index(a.bufferView, g_.bufferViews, name + ": bufferView");
  const auto& bv = g_.bufferViews[static_cast<std::size_t>(a.bufferView)];
  check_index(bv.buffer, g_.buffers, name + ": buffer");
  const auto& buffer = g_.buffers[static_cast<std::size_t>(bv.buffer)];
  const int comp_size = tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(a.componentType));
  const int comps = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
  if (comp_size <= 0 || comps <= 0) fail(name + ": unknown component or element type");
  const std::size_t elem = static_cast<std::size_t>(comp_size) * static_cast<std::size_t>(comps);
  const std::size_t stride = bv.byteStride > 0 ? bv.byteStride : elem;
  if (stride < elem) fail(name + ": byteStride " + std::to_string(stride) + " is smaller than the element");
  if (bv.byteOffset > buffer.data.size() || bv.byteLength > buffer.data.size() - bv.byteOffset)
    fail(name + ": bufferView " + std::to_string(a.bufferView) + " runs past the end of buffer " + std::to_string(bv.buffer) +
         " (" + std::to_string(buffer.data.size()) + " bytes loaded)");
  if (a.count > 0) {
    const std::size_t needed = a.byteOffset + stride * (a.count - 1) + elem;
    if (needed < a.byteOffset || needed > bv.byteLength)
      fail(name + ": " + std::to_string(a.count) + " elements need " + std::to_string(needed) + " bytes but bufferView " +
           std::to_string(a.bufferView) + " has " + std::to_string(bv.byteLength));
  }
  return {buffer.data.data() + bv.byteOffset + a.byteOffset, stride, a.count, a.componentType, a.type, a.normalized};
}

float GltfReader::read_component(const View& v, std::size_t i, int c) {
  const unsigned char* p = v.base + v.stride * i;
  switch (v.component_type) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p + 4 * c, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return static_cast<float>(p[c]) / (v.normalized ? 255.0F : 1.0F);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      const float f = static_cast<float>(static_cast<std::int8_t>(p[c]));
      return v.normalized ? std::max(f / 127.0F, -1.0F) : f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      std::uint16_t s;
      std::memcpy(&s, p + 2 * c, 2);
      return static_cast<float>(s) / (v.normalized ? 65535.0F : 1.0F);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      std::int16_t s;
      std::memcpy(&s, p + 2 * c, 2);
      return v.normalized ? std::max(static_cast<float>(s) / 32767.0F, -1.0F) : static_cast<float>(s);
    }
    default:
      return 0.0F;  // rejected by the callers' type checks
  }
}

void GltfReader::warn_once(const std::string& what) const {
  static std::mutex mutex;
  static std::set<std::string> said;
  std::lock_guard lock(mutex);
  if (said.insert(file_ + what).second) std::cerr << file_ << ": warning: " << what << '\n';
}

}  // namespace projbot::assets::detail
