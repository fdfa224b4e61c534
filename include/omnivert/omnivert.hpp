#pragma once
// omnivert: vertical lines in omnidirectional images, from pixels to the camera's pose on the
// robot (Scaramuzza, Siegwart, Martinelli, IJRR 2009). Start here.
//
// A catadioptric camera whose mirror axis is vertical sees every world vertical line as a
// radial line of its image. The library finds those lines, describes them, tracks them
// through a video and self-calibrates the camera-to-odometry extrinsics (phi, rho, psi; paper
// Fig. 19, docs/theory/conventions.md) from the line bearings and the wheel encoders.
//
// The entry points, one per stage of the pipeline:
//
//   omnivert::FeaturePipeline::process     one image -> mirror circle, radial lines with their
//                                          bearings, 192-D descriptors (Sec. 2-3)
//   omnivert::Tracker::add_frame           frame by frame -> a track id per line (Sec. 4, 9.1)
//   omnivert::pipeline::track_dataset      a whole dataset folder -> tracks.csv rows
//   omnivert::calib::calibrate             bearings + wheel increments -> extrinsics with
//                                          covariance, observability verdict, checks (Sec. 7-8)
//   omnivert::calib::CalibrationFilter     the same, frame by frame, as a robot drives (EKF)
//   omnivert::pipeline::calibrate_dataset  the main job: dataset folder -> every output file
//   omnivert::recording::import_recording  a ROS 1 / ROS 2 recording -> a dataset folder
//
// Example: the main job, then the same from the lines of each image.
//
//   #include <omnivert/omnivert.hpp>
//
//   auto r = omnivert::pipeline::calibrate_dataset("my_run", "my_run_calib");
//   std::printf("%s", r.BriefReport().c_str());        // estimate, sigmas, verdicts
//   Eigen::Matrix4d T = r.extrinsics().T_base_cam();   // camera pose in the robot frame
//
//   omnivert::FeaturePipeline frames(omnivert::load_camera_geometry("my_run/cam0/sensor.yaml"));
//   omnivert::FrameFeatures f;
//   std::string why;
//   if (!frames.process(image, f, &why)) { /* why says what is wrong with the image */ }
//   for (const omnivert::VerticalLine& l : f.lines) use(l.bearing);   // radians, (-pi, pi]
//
// Errors: bad input (files, data) throws omnivert::InputError naming the file, line and
// problem (core/error.hpp); invalid options are reported by their IsValid(&why).
//
// Each stage is also a library of its own (omnivert::core, extract, describe, match, dataset,
// recording, calib, sim, viz, pipeline, eval); omnivert::omnivert links them all. The estimator
// (omnivert::calib) needs only Eigen and Ceres.
//
// Namespaces: the image front end (core, image, extract, describe, match: cameras, images,
// lines, descriptors, tracks) is `omnivert`; every stage above it has its own, named after it:
// omnivert::dataset, recording, calib, sim, viz, pipeline, eval.

#include "omnivert/calib/calibrate.hpp"
#include "omnivert/calib/calibration_filter.hpp"
#include "omnivert/core/angles.hpp"
#include "omnivert/core/camera_geometry.hpp"
#include "omnivert/core/error.hpp"
#include "omnivert/dataset/dataset.hpp"
#include "omnivert/describe/feature_pipeline.hpp"
#include "omnivert/image/image_io.hpp"
#include "omnivert/match/tracker.hpp"
#include "omnivert/match/tracks_io.hpp"
#include "omnivert/pipeline/calibrate_dataset.hpp"
#include "omnivert/pipeline/track_dataset.hpp"
#include "omnivert/recording/import.hpp"
