// Hostile cases: outputs that would destroy an input (issue 47), and inputs that are not regular files.

#include "hostile_cases.hpp"

namespace hostile {

namespace {

// BoxTextured (a .gltf with its .bin and texture) copied under box/, and a scene s.yaml drawing it as
// target 'box' (`scene`), with `more` files beside.
const std::string kBoxScene =
    "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\n"
    "targets:\n  - name: box\n    model: box/BoxTextured.gltf\n    pose: {translation: [0, 0, 1]}\n";

Files box_files(const std::string& scene = kBoxScene, std::vector<std::pair<std::string, std::string>> more = {}) {
  const std::string from = "@head:10000000:{data}/gltf/BoxTextured/glTF/";
  Files f{{"box/BoxTextured.gltf", from + "BoxTextured.gltf"},
          {"box/BoxTextured0.bin", from + "BoxTextured0.bin"},
          {"box/CesiumLogoFlat.png", from + "CesiumLogoFlat.png"},
          {"s.yaml", scene}};
  for (auto& m : more) f.list.push_back(std::move(m));
  return f;
}

// A calibration file (calibrate solve's calib.yaml) for the 64x48 test projector.
const std::string kCalibration =
    "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\nprojector_from_camera: {translation: [0, 0, 0]}\n";

// The tour scene s.yaml taking its projector from calib.yaml (kCalibration) beside it.
Files calibrated_tour() {
  return Files{{"calib.yaml", kCalibration},
               {"s.yaml", "calibration: calib.yaml\n" + with(kTour, kRoomProjector, "projector: {near: 0.1, far: 10}\n")}};
}

}  // namespace

// Outputs that would destroy an input (issue 47): refused before any work, exit 2, naming both; inputs that
// are not regular files refused by kind, exit 1, before anything opens them (a FIFO would block).
std::vector<Hostile> clash_cases() {
  const std::string whole_rawlog = "@head:4000000:{rawlog}";
  std::string chain = R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [)";
  for (int i = 0; i < 20000; ++i) chain += R"({"children": [)" + std::to_string(i + 1) + "]},";
  chain += "{}]}";
  std::string doubling = R"({"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [)";  // 2^40 placements
  for (int i = 0; i < 40; ++i) doubling += R"({"children": [)" + std::to_string(i + 1) + ", " + std::to_string(i + 1) + "]},";
  doubling += "{}]}";
  return {
      Hostile{"ply_more_vertices_than_declared",
              "align --model {duck} --scan {dir}/c.ply",
              Files{{"c.ply",
                     "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\n"
                     "end_header\n0 0 1\n0 1 1\n1 0 1\n1 1 1\n"}},
              1,
              {"c.ply: the header declares 2 elements (2 vertices), the body holds 4 lines"}},
      Hostile{"gltf_texture_20000_pixels_a_side",
              "align --model {dir}/big.gltf --scan {data}/bunny/bun4.pcd",
              Files{{"big.gltf", R"({"asset": {"version": "2.0"}, "images": [{"uri": "big.png"}]})"},
                    {"big.png", png_claiming(20000, 20000)}},
              1,
              {"big.gltf: image 0: 20000x20000 pixels, larger than the 16384 pixels a side a texture may have"}},
      Hostile{"gltf_shared_children_doubling_40_levels",
              "align --model {dir}/dag.gltf --scan {data}/bunny/bun4.pcd",
              Files{{"dag.gltf", doubling}},
              1,
              {"dag.gltf: the node hierarchy places more than 100000 nodes"}},
      Hostile{"slam_ini_threshold_without_end",
              "slam --rawlog {rawlog} --config {dir}/huge.ini --out-map {dir}/m --out-trajectory {dir}/t.txt",
              Files{{"huge.ini", "[MappingApplication]\npointsMap_count=1\n[ICP]\nthresholdDist = 1e308\n"}},
              1,
              {"huge.ini:4: [ICP] thresholdDist = '1e308' must be 0.001..100"}},
      Hostile{"slam_ini_points_maps_that_crashed_mrpt",
              "slam --rawlog {rawlog} --config {dir}/maps.ini --out-map {dir}/m --out-trajectory {dir}/t.txt",
              Files{{"maps.ini", "[MappingApplication]\npointsMap_count = 100000\n[ICP]\nmaxIterations = 80\n"}},
              1,
              {"maps.ini:2: [MappingApplication] pointsMap_count = '100000' must be 1..4"}},
      Hostile{"slam_ground_truth_backwards",
              "slam --rawlog {rawlog} --ground-truth {dir}/gt.txt --out-map {dir}/m --out-trajectory {dir}/t.txt",
              Files{{"gt.txt", "2 0 0 0\n1 0 0 0\n"}},
              1,
              {"gt.txt:2: timestamp 1.000000 does not come after"}},
      Hostile{"localize_ground_truth_1e308",
              "localize --map {dir}/goodmap --rawlog {rawlog} --ground-truth {dir}/gt.txt --out-trajectory {dir}/t.txt",
              Files{{"gt.txt", "1 1e308 0 0\n"}},
              1,
              {"gt.txt:1: x and y must lie within 1000 km"}},
      Hostile{"scene_key_given_twice",
              "render --scene {dir}/bad.yaml --out {dir}/x.png",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets: []\nprojector: {width: 8}\n",
              1,
              {"bad.yaml:3: 'projector' is given twice in one mapping"}},
      Hostile{"scene_near_tiny",
              "render --scene {dir}/bad.yaml --out {dir}/x.png",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24, near: 1e-300, far: 10}\ntargets: []\n",
              1,
              {"bad.yaml", "0.0001 m <= near"}},
      Hostile{"scene_slip_scale_1e308",
              "tour --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets: []\n"
              "robot: {drift: {slip_scale: 1e308}}\n",
              1,
              {"robot.drift.slip_scale: must be 0..0.5"}},
      Hostile{"gltf_node_chain_20000_deep",
              "align --model {dir}/chain.gltf --scan {data}/bunny/bun4.pcd",
              Files{{"chain.gltf", chain}},
              1,
              {"chain.gltf: node 256: the node hierarchy is deeper than 256 levels"}},
      // The files a scene and its models name are inputs too (issue 72): a model's texture and buffer, a
      // target's model and surface print, a content video.
      Hostile{"render_out_over_the_models_texture",
              "render --model {dir}/box/BoxTextured.gltf --out {dir}/box/CesiumLogoFlat.png",
              box_files(),
              2,
              {"--out {dir}/box/CesiumLogoFlat.png is also the input part of the model of target 'model' "
               "{dir}/box/CesiumLogoFlat.png"}},
      Hostile{"render_profile_over_the_models_buffer",
              "render --model {dir}/box/BoxTextured.gltf --out {dir}/x.png --profile {dir}/box/BoxTextured0.bin",
              box_files(),
              2,
              {"--profile {dir}/box/BoxTextured0.bin is also the input part of the model of target 'model'"}},
      Hostile{"render_out_over_a_targets_surface_print",
              "render --scene {dir}/s.yaml --out {dir}/print.png",
              box_files(kBoxScene + "    surface: {texture: print.png}\n",
                        {{"print.png", "@head:100000:{data}/gltf/BoxTextured/glTF/CesiumLogoFlat.png"}}),
              2,
              {"--out {dir}/print.png is also the input the surface texture of target 'box'"}},
      Hostile{"tour_report_over_a_targets_model",
              "tour --scene {dir}/s.yaml --report {dir}/box/BoxTextured.gltf",
              box_files(kBoxScene),
              2,
              {"--report {dir}/box/BoxTextured.gltf is also the input the model of target 'box'"}},
      // Issue 88: the scene's calibration is an input like the scene (tour, run and render replaced it, exit 0).
      Hostile{"tour_report_over_the_calibration",
              "tour --scene {dir}/s.yaml --report {dir}/calib.yaml",
              calibrated_tour(),
              2,
              {"--report {dir}/calib.yaml is also the input the calibration of"}},
      Hostile{"run_profile_over_the_calibration",
              "run --headless --config {dir}/s.yaml --profile {dir}/calib.yaml",
              calibrated_tour(),
              2,
              {"--profile {dir}/calib.yaml is also the input the calibration of"}},
      // Issue 88: an output inside another output's folder (the report replaced a visit's picture).
      Hostile{"tour_report_inside_the_frames_folder",
              "tour --scene {dir}/s.yaml --frames {dir}/f --report {dir}/f/visit01_box.png",
              box_files(kBoxScene),
              2,
              {"--report {dir}/f/visit01_box.png is inside the output folder --frames {dir}/f"}},
      Hostile{
          "run_profile_inside_the_reflectance_folder",
          "run --headless --config {dir}/s.yaml --learn-reflectance --reflectance-out {dir}/r --profile {dir}/r/surfaces.yaml",
          calibrated_tour(),
          2,
          {"--profile {dir}/r/surfaces.yaml is inside the output folder --reflectance-out {dir}/r"}},
      Hostile{"bench_content_report_over_the_video",
              "bench content --scene {dir}/s.yaml --report {dir}/clip.mp4",
              box_files(kBoxScene + "    content: {video: clip.mp4}\n", {{"clip.mp4", "not a video, and must stay as it is"}}),
              2,
              {"--report {dir}/clip.mp4 is also the input the video of target 'box'"}},
      Hostile{"slam_out_map_holds_the_rawlog",
              "slam --rawlog {dir}/rec/laser.rawlog --out-map {dir}/rec --out-trajectory {dir}/t.txt",
              Files{{"rec/laser.rawlog", whole_rawlog}},
              2,
              {"--out-map {dir}/rec holds the input --rawlog {dir}/rec/laser.rawlog"}},
      Hostile{"slam_out_map_holds_other_files",
              "slam --rawlog {rawlog} --out-map {dir}/mine --out-trajectory {dir}/t.txt",
              Files{{"mine/notes.txt", "the user's\n"}},
              2,
              {"--out-map {dir}/mine: holds 'notes.txt', which this command did not write"}},
      Hostile{"slam_trajectory_over_the_rawlog",
              "slam --rawlog {dir}/r.rawlog --out-map {dir}/m --out-trajectory {dir}/r.rawlog",
              Files{{"r.rawlog", whole_rawlog}},
              2,
              {"--out-trajectory {dir}/r.rawlog is also the input --rawlog"}},
      Hostile{"localize_trajectory_over_the_map",
              "localize --map {dir}/goodmap --rawlog {rawlog} --out-trajectory {dir}/goodmap/map.simplemap.gz",
              "",
              2,
              {"is inside the input folder --map {dir}/goodmap"}},
      // Issue 43: the appearance bench's arguments and a scene's photometry.
      Hostile{"bench_appearance_report_over_the_scene",
              "bench appearance --scene {dir}/bad.yaml --report {dir}/bad.yaml",
              "a: 1\n",
              2,
              {"--report {dir}/bad.yaml is also the input --scene {dir}/bad.yaml"}},
      Hostile{"tour_compensation_maybe", "tour --compensation maybe", "", 2, {"--compensation must be on or off, not 'maybe'"}},
      Hostile{"run_compensation_empty", "run --sim --headless --compensation ''", "", 2, {"--compensation must be on or off"}},
      Hostile{"calibrate_photometric_no_out", "calibrate photometric --sim", "", 2, {"--out FILE is required"}},
      Hostile{
          "calibrate_photometric_noise_nan", "calibrate photometric --sim --noise nan --out {dir}/p.yaml", "", 2, {"--noise"}},
      Hostile{"calibrate_photometric_camera_response_brackets",
              "calibrate photometric --sim --camera-response brackets --out {dir}/p.yaml",
              "",
              2,
              {"--camera-response can only be 'colours'"}},
      Hostile{"calibrate_photometric_gamma_and_colours",
              "calibrate photometric --config {dir}/bad.yaml --camera-gamma 2.2 --camera-response colours --out {dir}/p.yaml",
              "a: 1\n",
              2,
              {"give the camera's gamma or have it measured, not both"}},
      Hostile{"calibrate_photometric_sim_and_config",
              "calibrate photometric --sim --config {dir}/bad.yaml --out {dir}/p.yaml",
              "a: 1\n",
              2,
              {"--sim and --config: give one"}},
      Hostile{"calibrate_photometric_sim_settle",
              "calibrate photometric --sim --settle-ms 100 --out {dir}/p.yaml",
              "",
              2,
              {"--settle-ms is for the projector window of --config, not --sim"}},
      Hostile{"calibrate_photometric_config_noise",
              "calibrate photometric --config {dir}/bad.yaml --noise 3 --out {dir}/p.yaml",
              "a: 1\n",
              2,
              {"--noise is the twin's (--sim)"}},
      Hostile{"calibrate_photometric_out_over_config",
              "calibrate photometric --config {dir}/bad.yaml --out {dir}/bad.yaml",
              "a: 1\n",
              2,
              {"--out {dir}/bad.yaml is also the input --config {dir}/bad.yaml"}},
      // Issue 72: a room this bright gave gammas 34 % off the truth with exit 0.
      Hostile{"calibrate_photometric_room_too_bright",
              "calibrate photometric --sim --scene {dir}/bad.yaml --out {dir}/p.yaml",
              kRoomProjector +
                  "room: {width: 6, depth: 5, ambient_lux: 100000}\ntargets:\n  - {name: duck, model: {duck}, scale: "
                  "0.25, pose: {translation: [0, 0, 1]}}\n",
              1,
              {"the ramps miss their fitted curves by", "(RMS, worst channel; allowed 2 %)", "darken the room"}},
      Hostile{"calibrate_photometric_out_over_scene",
              "calibrate photometric --sim --scene {dir}/bad.yaml --out {dir}/bad.yaml",
              "a: 1\n",
              2,
              {"--out {dir}/bad.yaml is also the input --scene {dir}/bad.yaml"}},
      Hostile{"bench_appearance_reflectance_bad",
              "bench appearance --reflectance guessed",
              "",
              2,
              {"--reflectance must be scene, measured or mapped, not 'guessed'"}},
      Hostile{"bench_appearance_dwell_zero", "bench appearance --dwell 0", "", 2, {"--dwell must be 0.1..3600 seconds"}},
      Hostile{"bench_appearance_gamma_nan",
              "bench appearance --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24, gamma: .nan}\ntargets: []\n",
              1,
              {"bad.yaml:1:", "projector.gamma"}},
      Hostile{"scene_albedo_negative",
              "tour --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\n"
              "targets:\n  - {name: a, model: a.glb, pose: {translation: [0, 0, 1]}, surface: {albedo: [-1, 0, 0]}}\n",
              1,
              {"targets[0].surface.albedo: each of r, g, b must be 0..1"}},
      // Issue 44: a target's video, bad at load: one line naming the file, exit 1, nothing written.
      Hostile{"bench_content_video_missing",
              "bench content --scene {dir}/bad.yaml --report {dir}/r.json",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {video: missing.mp4}}\n",
              1,
              {"missing.mp4: does not exist"}},
      Hostile{"bench_content_video_noise",
              "bench content --scene {dir}/bad.yaml --report {dir}/r.json",
              Files{{"bad.yaml",
                     "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, "
                     "scale: 0.25, pose: {translation: [0, 0, 1]}, content: {video: noise.mp4}}\n"},
                    {"noise.mp4", "@random:20000"}},
              1,
              {"noise.mp4: not a video FFmpeg can read"}},
      Hostile{"bench_content_video_truncated",
              "bench content --scene {dir}/bad.yaml",
              Files{{"bad.yaml",
                     "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, "
                     "scale: 0.25, pose: {translation: [0, 0, 1]}, content: {video: cut.mp4}}\n"},
                    {"cut.mp4", "@head:4000:{made}/videos/countdown.mp4"}},
              1,
              {"cut.mp4: "}},
      Hostile{"bench_content_video_mov_table_713mb",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {video: {src}/tests/hostile/mp4_table_713mb.mp4}}\n",
              1,
              {"mp4_table_713mb.mp4: "}},
      Hostile{"bench_content_video_is_a_folder",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {video: goodmap}}\n",
              1,
              {"goodmap: is not a regular file"}},
      Hostile{"bench_content_material_missing",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {video: {made}/videos/countdown.mp4, material: glass}}\n",
              1,
              {"no material 'glass' for the content"}},
      // Issue 72: a mesh without texture coordinates took one pixel of the video everywhere, silently.
      Hostile{
          "bench_content_video_on_a_mesh_without_uvs",
          "bench content --scene {dir}/bad.yaml",
          "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: can, model: "
          "{data}/ycbv-bop/models/obj_000001.ply, scale: 0.001, pose: {translation: [0, 0, 1]}, content: {video: "
          "{made}/videos/countdown.mp4}}\n",
          1,
          {"countdown.mp4: target 'can's video needs texture coordinates to lie on, and its model", "obj_000001.ply has none"}},
      // Issue 72: FFmpeg's error code for it is EBUSY, "Device or resource busy"; its log says the size.
      Hostile{
          "bench_content_video_20000_pixels_a_side",
          "bench content --scene {dir}/bad.yaml",
          Files{{"bad.yaml",
                 "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: box, model: "
                 "{data}/gltf/BoxTextured/glTF/BoxTextured.gltf, pose: {translation: [0, 0, 1]}, content: {video: big.y4m}}\n"},
                {"big.y4m", "YUV4MPEG2 W20000 H20000 F30:1 Ip A1:1 C420jpeg\nFRAME\n"}},
          1,
          {"big.y4m: not a video FFmpeg can read (Picture size 20000x20000 is invalid; this player takes at most 8192 px"}},
      // "(it has 0)" read as no materials where the box has one, unnamed.
      Hostile{"bench_content_material_missing_on_an_unnamed_one",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: box, model: "
              "{data}/gltf/BoxTextured/glTF/BoxTextured.gltf, pose: {translation: [0, 0, 1]}, content: {video: "
              "{made}/videos/countdown.mp4, material: nosuch}}\n",
              1,
              {"no material 'nosuch' for the content (its 1 material: 0 (unnamed))"}},
      // Issue 72: 300 targets with videos of their own ended in "Resource temporarily unavailable".
      Hostile{"bench_content_more_videos_than_decoders",
              "bench content --scene {dir}/bad.yaml",
              [] {
                std::string yaml = "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n";
                for (int i = 0; i < 65; ++i)
                  yaml += "  - {name: t" + std::to_string(i) + ", model: {duck}, scale: 0.25, pose: {translation: [0, 0, 1]}, " +
                          "content: {video: {made}/videos/countdown.mp4, start: " + std::to_string(i) + "}}\n";
                return yaml;
              }(),
              1,
              {"bad.yaml: 65 videos would play at once, each with its own decoder; at most 64 do"}},
      Hostile{"bench_content_without_content",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets: []\n",
              1,
              {"no target has `content:` to play"}},
      Hostile{"render_content_time_negative",
              "render --out {dir}/x.png --content-time -1",
              "",
              2,
              {"--content-time must be 0..1e6 seconds"}},
      Hostile{"bench_content_seconds_zero", "bench content --seconds 0", "", 2, {"--seconds must be 0.1..86400"}},
      Hostile{"scene_content_timeline_backwards",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {timeline: [{at_s: 1, base_color_factor: [1, 1, 1, 1]}, {at_s: "
              "0.5, base_color_factor: [0, 0, 0, 1]}]}}\n",
              1,
              {"content.timeline[1].at_s: must come after the key before it"}},
      Hostile{"scene_content_timeline_colour_over_one",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {timeline: [{at_s: 0, base_color_factor: [2, 1, 1, 1]}]}}\n",
              1,
              {"content.timeline[0].base_color_factor: each of r, g, b, a must be 0..1"}},
      Hostile{"scene_content_start_tomorrow",
              "bench content --scene {dir}/bad.yaml",
              "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\ntargets:\n  - {name: a, model: {duck}, scale: "
              "0.25, pose: {translation: [0, 0, 1]}, content: {video: a.mp4, start: tomorrow}}\n",
              1,
              {"content.start: expected arrival, tour or 0..1e6 seconds", "'tomorrow'"}},
      Hostile{"tour_report_over_the_scene",
              "tour --scene {dir}/bad.yaml --report {dir}/bad.yaml",
              "a: 1\n",
              2,
              {"--report {dir}/bad.yaml is also the input --scene {dir}/bad.yaml"}},
      Hostile{"tour_report_over_the_scene_through_a_link",
              "tour --scene {dir}/link.yaml --report {dir}/bad.yaml",
              Files{{"bad.yaml", "a: 1\n"}, {"link.yaml", "@link:bad.yaml"}},
              2,
              {"is also the input --scene {dir}/link.yaml"}},
      Hostile{"render_profile_over_the_scene",
              "render --scene {dir}/bad.yaml --out {dir}/x.png --profile {dir}/bad.yaml",
              "a: 1\n",
              2,
              {"--profile {dir}/bad.yaml is also the input --scene"}},
      Hostile{"render_out_and_profile_one_file", "render --out {dir}/x.png --profile {dir}/x.png", "", 2, {"are the same path"}},
      Hostile{"calibrate_solve_out_over_its_manifest",
              "calibrate solve {dir}/cap --out {dir}/cap/capture.yaml",
              Files{{"cap/capture.yaml", "projector: [8, 8]\n"}},
              2,
              {"--out {dir}/cap/capture.yaml is inside the input folder the folder {dir}/cap"}},
      Hostile{"run_replay_profile_over_its_poses",
              "run --headless --replay {dir}/rec --profile {dir}/rec/poses.csv",
              Files{{"rec/poses.csv", "frame\n"}, {"rec/recording.yaml", "a: 1\n"}},
              2,
              {"--profile {dir}/rec/poses.csv is inside the input folder --replay {dir}/rec"}},
      Hostile{"tour_scene_is_a_fifo",
              "tour --scene {dir}/f.yaml",
              Files{{"f.yaml", "@fifo"}},
              1,
              {"--scene {dir}/f.yaml: is a FIFO, not a regular file"}},
      Hostile{"align_scan_is_a_fifo",
              "align --model {duck} --scan {dir}/f.pcd",
              Files{{"f.pcd", "@fifo"}},
              1,
              {"--scan {dir}/f.pcd: is a FIFO, not a regular file"}},
      Hostile{"gltf_buffer_is_a_fifo",
              "align --model {dir}/m.gltf --scan {data}/bunny/bun4.pcd",
              Files{{"m.gltf", R"({"asset": {"version": "2.0"}, "buffers": [{"uri": "f.bin", "byteLength": 12}]})"},
                    {"f.bin", "@fifo"}},
              1,
              {"f.bin' is a FIFO, not a regular file"}},
      Hostile{"scene_model_is_a_fifo",
              "render --scene {dir}/s.yaml --out {dir}/x.png",
              Files{{"s.yaml",
                     "projector: {width: 64, height: 48, fx: 50, fy: 50, cx: 32, cy: 24}\n"
                     "targets:\n  - {name: a, model: f.glb, pose: {translation: [0, 0, 1]}}\n"},
                    {"f.glb", "@fifo"}},
              1,
              {"f.glb: is a FIFO, not a regular file"}},
      Hostile{"obj_material_library_is_a_fifo",  // issue 72: Assimp blocked on it until its time limit, blaming the OBJ
              "render --model {dir}/m.obj --out {dir}/x.png",
              Files{{"m.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n"}, {"m.mtl", "@fifo"}},
              1,
              {"m.mtl: is a FIFO, not a regular file (the material library {dir}/m.obj names)"}},
      Hostile{"render_scene_is_dev_zero",
              "render --scene /dev/zero --out {dir}/x.png",
              "",
              1,
              {"--scene /dev/zero: is a character device, not a regular file"}},
      Hostile{"slam_rawlog_is_dev_zero",
              "slam --rawlog /dev/zero --out-map {dir}/m --out-trajectory {dir}/t.txt",
              "",
              1,
              {"--rawlog /dev/zero: is a character device"}},
  };
}

}  // namespace hostile
