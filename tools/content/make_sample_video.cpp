// Writes the shipped content scene's video at build time (it is made, not committed): a clip whose frames
// show their own number (assets::frame_code_image), so that a rendered frame says which video frame it shows.
//   projbot_make_video OUT.mp4 WIDTH HEIGHT FPS SECONDS
#include <cstdlib>
#include <iostream>
#include <string>

#include "projbot/assets/video.hpp"

int main(int argc, char** argv) {
  if (argc != 6) {
    std::cerr << "usage: projbot_make_video OUT.mp4 WIDTH HEIGHT FPS SECONDS\n";
    return 2;
  }
  try {
    const int width = std::stoi(argv[2]), height = std::stoi(argv[3]), fps = std::stoi(argv[4]);
    const int frames = fps * std::stoi(argv[5]);
    std::filesystem::create_directories(std::filesystem::path(argv[1]).parent_path());
    projbot::assets::VideoWriter writer(argv[1], width, height, fps);
    for (int i = 0; i < frames; ++i) writer.write(projbot::assets::frame_code_image(i, width, height));
    writer.finish();
  } catch (const std::exception& e) {
    std::cerr << "projbot_make_video: " << e.what() << '\n';
    return 1;
  }
  return 0;
}
