#pragma once
// What an encoded image's header claims, read by our private stb (image.cpp) without decoding it.

namespace projbot::assets::detail {

/// The width and height a PNG / JPEG / ... in memory claims; false when stb cannot tell.
bool claimed_image_size(const unsigned char* bytes, int size, int& width, int& height);

/// The largest texture side the renderer takes (Vulkan's guaranteed-on-every-GPU maxImageDimension2D is
/// 4096; lavapipe and current GPUs take 16384): a larger image is refused before it is decoded.
inline constexpr int kMaxTextureSide = 16384;

}  // namespace projbot::assets::detail
