// A capture without masks, as most COLMAP users have: the generated scene on a textured floor that
// runs on beyond the volume, in a textured room, photographed from a ring, its exact masks kept
// out of the project. Carved and held out at the defaults and with the colour test off.
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/test_support.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;
using testing::JsonNumber;
using testing::RunRaycarve;

// The whole run's figure in holdout.json: its key comes last, after each view's own.
double Overall(const std::string& holdout_json, const std::string& key) {
  return JsonNumber(holdout_json.substr(holdout_json.rfind("\"" + key + "\":")), key);
}

// <root>/scene held out (every 4th photo) with `flags` into <root>/<name>, scored inside the
// truth's silhouettes (<root>/truth_masks, which the carve never sees): its holdout.json.
std::string HeldOut(const std::string& root, const std::string& name, const std::string& flags) {
  std::string output;
  EXPECT_EQ(RunRaycarve("holdout --workspace_path " + root + "/scene --every 4 --output_path " +
                            root + "/" + name + " --score_mask_path " + root + "/truth_masks" +
                            flags,
                        &output),
            0)
      << output;
  return testing::ReadFileBytes(root + "/" + name + "/holdout/holdout.json");
}

// The F-score at two voxels of <root>/scene's carve (report.json's volume and voxel) against its
// truth, inside the volume carved.
double FScoreInVolume(const std::string& root, const std::string& report) {
  const std::string scene = root + "/scene";
  std::string output;
  EXPECT_EQ(RunRaycarve("compare --reference_path " + scene + "/truth.ply --input_path " + scene +
                            "/raycarve/cloud.ply --threshold " +
                            std::to_string(2.0 * JsonNumber(report, "voxel_size")) + " --bbox " +
                            testing::ReportBoxText(report) + " --output_path " + root +
                            "/compare.json",
                        &output),
            0)
      << output;
  return JsonNumber(testing::ReadFileBytes(root + "/compare.json"), "f_score");
}

// A generated scene (raycarve synth with `flags`, 12 photos of 320x240) in <root>/scene, its exact
// masks moved to <root>/truth_masks, out of the project: what a user without masks has. Returns
// <root>/scene.
std::string SceneWithoutMasks(const std::string& root, const std::string& flags) {
  const std::string scene = root + "/scene";
  std::string output;
  EXPECT_EQ(RunRaycarve("synth --output_path " + scene + " --views 12 --width 320 --height 240 " +
                            flags,
                        &output),
            0)
      << output;
  fs::rename(scene + "/masks", root + "/truth_masks");
  return scene;
}

TEST(UnmaskedCapture, TheSubjectIsCarvedInItsOwnBoxWithoutTheBoxsWalls) {
  const std::string root = testing::MakeTemporaryDirectory("unmasked_capture");
  const std::string scene = SceneWithoutMasks(root, "--backdrop room");
  std::string output;
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + scene, &output), 0) << output;
  // The cameras stand around the subject: the box goes round their focus, and the summary says
  // what would help (masks).
  EXPECT_NE(output.find("cameras around a point (object-centred)"), std::string::npos) << output;
  EXPECT_NE(output.find("the volume: the box around their focus"), std::string::npos) << output;
  EXPECT_NE(output.find("give the subject's masks (--mask_path"), std::string::npos) << output;
  const std::string report = testing::ReadFileBytes(scene + "/raycarve/report.json");
  EXPECT_NE(report.find("\"kind\": \"object\""), std::string::npos);
  EXPECT_NE(report.find("\"around_focus\": true"), std::string::npos);
  EXPECT_GT(JsonNumber(report, "box_wall_triangles_removed"), 0);
  // An object's closed mesh keeps what no photo sees (its foot, its underside).
  EXPECT_EQ(JsonNumber(report, "unseen_triangles_removed"), 0);
  // The floor under the subject: found from the sparse points, said in the summary.
  EXPECT_NE(report.find("\"supporting_plane\": {\n      \"found\": true"), std::string::npos)
      << report.substr(report.find("\"supporting_plane\""), 200);
  EXPECT_GT(JsonNumber(report, "on_plane_share"), 0.2);
  EXPECT_NE(output.find("a supporting plane: normal"), std::string::npos) << output;
  // Cameras around the subject, no masks: the threshold is at least a voxel's spread.
  EXPECT_EQ(JsonNumber(report, "spread_floor"), 1.0);
  EXPECT_NE(report.find("\"spread_floor_reason\": \"an object without masks"),
            std::string::npos);
  EXPECT_NE(output.find("at least 1 x a voxel's within-view spread"), std::string::npos)
      << output;
  // Likewise the threshold is measured on every photo that sees each sparse point through a first
  // pass of the coarsest level, not on its track alone (synth's tracks already hold every photo
  // that sees the point, so here the views a point barely grow).
  EXPECT_NE(report.find("\"threshold_views\": \"seen\""), std::string::npos);
  EXPECT_NE(report.find("\"first_pass\": {"), std::string::npos);
  EXPECT_GE(JsonNumber(report, "views_per_point"), JsonNumber(report, "track_views_per_point"));
  EXPECT_NE(output.find("judged from every photo that sees it"), std::string::npos) << output;
  EXPECT_NE(output.find("photos a sparse point that see it, not its track's"), std::string::npos)
      << output;
  // The cloud against the truth (the objects, the ground square and the room's floor) inside the
  // volume, at two voxels (measured: F-score 99.0%).
  EXPECT_GT(FScoreInVolume(root, report), 0.88);
  // Held out, scored inside the truth's silhouettes and against the photos' sparse points: the
  // colour test against no colour test (measured: 23.96 against 16.64 dB; 94.0% of the sparse
  // points at their depth and 3.4% hidden, against 59.7% and 39.5%: the ground pixels' free
  // space, which colour off keeps, opens the floor's surroundings to it too).
  const std::string defaults = HeldOut(root, "defaults", "");
  const std::string colour_off = HeldOut(root, "colour_off", " --threshold 1000000");
  EXPECT_GT(JsonNumber(defaults, "mean_psnr_db"), JsonNumber(colour_off, "mean_psnr_db") + 5.0);
  EXPECT_GT(Overall(defaults, "sparse_points"), 1000);
  EXPECT_GT(Overall(defaults, "sparse_at_depth_share"), 0.9);
  EXPECT_LT(Overall(defaults, "sparse_hidden_share"), 0.05);
  EXPECT_LT(Overall(colour_off, "sparse_at_depth_share"), Overall(defaults, "sparse_at_depth_share") - 0.25);
}

// The same room with the subject's masks given: the masks bound the subject, but the room's
// sparse points still widen the box the points give. The box is narrowed to the masks' visual
// hull where the sparse points are, and the subject's voxels become finer.
// The room scene (SceneWithoutMasks with --backdrop room and `flags`) in <root>, carved at the
// defaults with its exact masks given: the scene; the carve's output in *output.
std::string MaskedRoomCarved(const std::string& root, const std::string& flags,
                             std::string* output) {
  const std::string scene = SceneWithoutMasks(root, "--backdrop room" + flags);
  EXPECT_EQ(RunRaycarve("carve --workspace_path " + scene + " --mask_path " + root + "/truth_masks",
                        output),
            0)
      << *output;
  return scene;
}

TEST(UnmaskedCapture, MasksGivenInARoomNarrowTheBoxToTheSubject) {
  const std::string root = testing::MakeTemporaryDirectory("masked_room");
  std::string output;
  const std::string scene = MaskedRoomCarved(root, "", &output);
  const std::string masks = " --mask_path " + root + "/truth_masks";
  EXPECT_NE(output.find("the volume: the box around what the masks call the object"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("in the box narrowed to the masks"), std::string::npos) << output;
  const std::string report = testing::ReadFileBytes(scene + "/raycarve/report.json");
  EXPECT_NE(report.find("\"around_hull\": true"), std::string::npos);
  // --capture scene keeps the points' box.
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + scene + masks +
                            " --capture scene --output_path " + root + "/points_box",
                        &output),
            0)
      << output;
  const std::string points_box = testing::ReadFileBytes(root + "/points_box/report.json");
  EXPECT_NE(points_box.find("\"around_hull\": false"), std::string::npos);
  // The narrower box would make a voxel span 1.37 pixels of these small photos against the
  // points' box's 1.97: the default resolution is lowered so that it spans as many as before
  // (no fewer than 3 where the points' box gave more), and the box holds fewer voxels.
  EXPECT_EQ(JsonNumber(report, "hull_lowered_from"), 128);
  EXPECT_EQ(JsonNumber(points_box, "hull_lowered_from"), 0);
  EXPECT_NEAR(JsonNumber(report, "voxel_size"), JsonNumber(points_box, "voxel_size"),
              0.02 * JsonNumber(points_box, "voxel_size"));
  EXPECT_LT(JsonNumber(report, "num_voxels"), 0.6 * JsonNumber(points_box, "num_voxels"));
  // Nothing of the subject is cut: the cloud against the truth inside the narrower box (measured:
  // F-score 99.5%), and the held-out photos' silhouettes (measured: IoU 0.985). (Their PSNR is
  // not compared: on 9 photos of 320x240 it swings by 1-2 dB with the grid, either way; on 36 of
  // 640x480 the narrower box gained 3.0 dB, docs/studies/2026-12-06-hull-box.md.)
  EXPECT_GT(FScoreInVolume(root, report), 0.95);
  const std::string narrowed = HeldOut(root, "narrowed", masks);
  EXPECT_GT(JsonNumber(narrowed, "mean_silhouette_iou"), 0.97);
}

// At 640x480 the narrowed box at the default 128 voxels would make a voxel span 2.7 pixels
// against the points' box's 3.9: the resolution is lowered so that it spans 3. A resolution
// given is kept.
TEST(UnmaskedCapture, TheNarrowedBoxsVoxelSpansThreePixelsAtTheDefault) {
  const std::string root = testing::MakeTemporaryDirectory("masked_room_vga");
  std::string output;
  const std::string scene = MaskedRoomCarved(root, " --width 640 --height 480", &output);
  const std::string masks = " --mask_path " + root + "/truth_masks";
  const std::string report = testing::ReadFileBytes(scene + "/raycarve/report.json");
  EXPECT_NE(report.find("\"around_hull\": true"), std::string::npos);
  EXPECT_EQ(JsonNumber(report, "hull_lowered_from"), 128);
  EXPECT_NEAR(JsonNumber(report, "voxel_pixels"), 3.0, 0.05);
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + scene + masks +
                            " --resolution 128 --output_path " + root + "/given",
                        &output),
            0)
      << output;
  const std::string given = testing::ReadFileBytes(root + "/given/report.json");
  EXPECT_EQ(JsonNumber(given, "hull_lowered_from"), 0);
  EXPECT_LT(JsonNumber(given, "voxel_pixels"), 2.9);
  EXPECT_GT(JsonNumber(given, "voxel_pixels"), 2.0);
}

// An object amid clutter: blocks standing around it, some between the arc of cameras and the
// objects. The box around the cameras' focus grows to hold the sparse points that hide parts of
// the subject from some photos, so that the carve sees what stands in front of the subject
// instead of painting the subject with it.
TEST(UnmaskedCapture, WhatStandsInFrontOfTheSubjectIsInTheVolume) {
  const std::string root = testing::MakeTemporaryDirectory("unmasked_clutter");
  const std::string scene = SceneWithoutMasks(root, "--scene clutter --backdrop room --layout arc");
  std::string output;
  // Without the ground pixels' free space first: between the clutter and the objects, where few
  // photos see, the photos agree on much that is empty over the floor.
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + scene + " --ground_free_space 0", &output), 0) << output;
  const std::string without_ground = testing::ReadFileBytes(scene + "/raycarve/report.json");
  const double f_without_ground = FScoreInVolume(root, without_ground);
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + scene, &output), 0) << output;
  EXPECT_NE(output.find("in front of them that hide some of them from photos"), std::string::npos)
      << output;
  const std::string report = testing::ReadFileBytes(scene + "/raycarve/report.json");
  const std::string ground = report.substr(report.find("\"ground_pixels\""));
  EXPECT_GT(JsonNumber(ground, "found_pixels"), 1000) << ground.substr(0, 300);
  EXPECT_GT(JsonNumber(ground, "voxels_carved"), 1000) << ground.substr(0, 300);
  EXPECT_NE(output.find("ground seen: "), std::string::npos) << output;
  EXPECT_GE(JsonNumber(report, "occluder_points"), 10);
  // The bench in front of the arc's middle cameras (x in [-0.35, 0.55], y in [2.075, 2.425]) is
  // inside the volume.
  const std::string box = testing::ReportBoxText(report);
  std::vector<double> corners;
  std::stringstream stream(box);
  for (std::string value; std::getline(stream, value, ',');) corners.push_back(std::stod(value));
  ASSERT_EQ(corners.size(), 6u) << box;
  EXPECT_GT(corners[4], 2.425) << box;
  // Measured: F-score 86.9% without the ground pixels, 91.7% with them.
  const double f = FScoreInVolume(root, report);
  EXPECT_GT(f, 0.85);
  EXPECT_GT(f, f_without_ground + 0.02) << f_without_ground << " -> " << f;
  // Held out inside the truth's silhouettes (measured: 22.85 dB against 19.51 with the colour
  // test off; 91.4% of the sparse points at their depth, 3.7% hidden).
  const std::string defaults = HeldOut(root, "defaults", "");
  const std::string colour_off = HeldOut(root, "colour_off", " --threshold 1000000");
  EXPECT_GT(JsonNumber(defaults, "mean_psnr_db"), JsonNumber(colour_off, "mean_psnr_db") + 1.5);
  EXPECT_GT(Overall(defaults, "sparse_at_depth_share"), 0.85);
  EXPECT_LT(Overall(defaults, "sparse_hidden_share"), 0.08);
  // Carved in tiles with the distant pixels off, a job still takes the ground pixels' rays from
  // its plan (the plan's ray file holds them).
  ASSERT_EQ(RunRaycarve("tile plan --workspace_path " + scene + " --output_path " + root +
                            "/tiled --tiles 2 --tile_path " + root + "/tiles --distant_free_space 0",
                        &output),
            0)
      << output;
  ASSERT_EQ(RunRaycarve("tile run --plan " + root + "/tiles/plan.json --index 0", &output), 0) << output;
  const size_t taken = output.find(" rays of distant and ground pixels from the tile plan");
  ASSERT_NE(taken, std::string::npos) << output;
  const size_t line = output.rfind(']', taken);
  EXPECT_GT(std::stol(output.substr(line + 1, taken - line - 1)), 1000) << output.substr(line, 80);
}

// Forward-facing photos (a grid of positions in front of the scene, as before a facade): a scene,
// whose box keeps every sparse point the filters keep.
// Forward-facing photos of the room scene: a scene, not an object. Its box holds the sparse
// points the photos place in depth (the room's far wall, 13 away behind a baseline of 2, is
// placed worse: measured 475 of 516 points kept), and the floor under it is held.
TEST(UnmaskedCapture, ForwardFacingPhotosAreASceneBoxedToTheDepthTheyPlace) {
  const std::string root = testing::MakeTemporaryDirectory("unmasked_forward");
  std::string output;
  ASSERT_EQ(RunRaycarve("synth --output_path " + root + " --layout forward --backdrop room "
                        "--views 8 --width 128 --height 96 --points 600",
                        &output),
            0)
      << output;
  fs::remove_all(root + "/masks");
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + root + " --resolution 32", &output), 0) << output;
  EXPECT_NE(output.find("cameras facing one way (a scene)"), std::string::npos) << output;
  const std::string report = testing::ReadFileBytes(root + "/raycarve/report.json");
  EXPECT_NE(report.find("\"kind\": \"scene\""), std::string::npos);
  EXPECT_NE(report.find("\"around_focus\": false"), std::string::npos);
  // Seen from one side: no spread floor.
  EXPECT_EQ(JsonNumber(report, "spread_floor"), 0.0);
  EXPECT_NE(report.find("\"spread_floor_reason\": \"none: a scene"), std::string::npos);
  EXPECT_EQ(output.find("x a voxel's within-view spread"), std::string::npos) << output;
  EXPECT_NE(report.find("\"threshold_views\": \"tracks\""), std::string::npos);
  EXPECT_EQ(report.find("\"first_pass\""), std::string::npos);
  const double tried = JsonNumber(report, "depth_tried_points");
  const double resolved = JsonNumber(report, "depth_resolved_points");
  EXPECT_GT(tried, 400);
  EXPECT_LT(resolved, tried);
  EXPECT_GE(resolved, 0.5 * tried);
  EXPECT_NE(output.find("sparse points the photos place in depth to two voxels"), std::string::npos)
      << output;
  EXPECT_NE(report.find("\"ground_held\": true"), std::string::npos);
  EXPECT_GT(JsonNumber(report, "ground_voxels"), 0);
  // The space near the cameras and beside their frames is never judged and stays solid; its face
  // towards the seen space is no surface: left out of the mesh.
  EXPECT_GT(JsonNumber(report, "beyond_frames_triangles_removed"), 0);
  EXPECT_NE(output.find("beyond the frames of all but one photo"), std::string::npos) << output;
  // Behind the sphere and the box, where every photo's view is blocked, the carve judged nothing
  // and kept the space solid: its surface is left out too.
  EXPECT_GT(JsonNumber(report, "unseen_triangles_removed"), 0);
  EXPECT_NE(output.find("behind the subjects from every camera"), std::string::npos) << output;
  // But not within a voxel of what two photos see: the subjects' rims stay closed.
  EXPECT_GT(JsonNumber(report, "unseen_vertices_kept"), 0);
  EXPECT_NE(output.find("open where the box cuts the scene, beyond the photos' frames and behind "
                        "the subjects"),
            std::string::npos)
      << output;
  // The generated points are exact: the densest plane is the ground itself.
  EXPECT_NE(report.find("\"densest_plane_passed_over\": false"), std::string::npos);
  EXPECT_EQ(report.find("densest_plane_on_share"), std::string::npos);
  // The same with --capture scene: every point, no narrowing.
  ASSERT_EQ(RunRaycarve("carve --workspace_path " + root + " --resolution 32 --capture scene "
                        "--output_path " + root + "/all_points",
                        &output),
            0)
      << output;
  const std::string all_points = testing::ReadFileBytes(root + "/all_points/report.json");
  EXPECT_EQ(JsonNumber(all_points, "depth_tried_points"), 0);
}

// Objects photographed on foot (the arc at their height) under a cloudy sky over a field, carved
// without masks (as where the backdrop rule misses the sky): the blue between the clouds agrees
// across the photos through the empty space in front of it, which colour alone keeps; the
// distant pixels (cloud edges moving as the sky does, the plain blue they bound) carve it.
TEST(UnmaskedCapture, PixelsThatShowTheSkyCarveTheSpaceInFrontOfIt) {
  const std::string root = testing::MakeTemporaryDirectory("unmasked_sky");
  const std::string scene = SceneWithoutMasks(root, "--layout eye_level --backdrop cloudy");
  std::string output;
  const auto carve = [&](const std::string& flags) {
    EXPECT_EQ(RunRaycarve("carve --workspace_path " + scene + " --background_colour none" + flags,
                          &output),
              0)
        << output;
    return testing::ReadFileBytes(scene + "/raycarve/report.json");
  };
  const std::string without = carve(" --distant_free_space 0");
  const double f_without = FScoreInVolume(root, without);
  EXPECT_EQ(JsonNumber(without, "distant_voxels_carved"), 0);
  const std::string with = carve("");
  const double f_with = FScoreInVolume(root, with);
  EXPECT_GT(JsonNumber(with, "found_pixels"), 100);
  EXPECT_GT(JsonNumber(with, "distant_voxels_carved"), 1000);
  EXPECT_NE(output.find("distant: "), std::string::npos) << output;
  // Measured: F 65.4% -> 79.1%.
  EXPECT_GT(f_with, f_without + 0.06) << f_without << " -> " << f_with;
}

}  // namespace
}  // namespace raycarve
