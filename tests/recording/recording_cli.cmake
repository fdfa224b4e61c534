# The tool on the fixtures' recordings: --config on import, track and calibrate (the file's
# options applied, the command line's winning, an unknown key or a refused value named with the
# file and line); track and calibrate on a recording (OUT/dataset removed unless
# --keep-dataset); the prior of a recording's /tf_static named on the terminal.
# -DOV=omnivert -DFX=fixtures -DTD=scratch folder
function(run expect)  # run(EXIT_CODE command...): sets OUT and ERR
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL expect)
    message(FATAL_ERROR "${ARGN}\nexpected exit code ${expect}, got ${rc}\nstdout: ${out}\nstderr: ${err}")
  endif()
  set(OUT "${out}" PARENT_SCOPE)
  set(ERR "${err}" PARENT_SCOPE)
endfunction()
function(expect_match text regex)
  if(NOT "${text}" MATCHES "${regex}")
    message(FATAL_ERROR "expected a match of '${regex}' in:\n${text}")
  endif()
endfunction()
file(REMOVE_RECURSE ${TD})
file(MAKE_DIRECTORY ${TD})

# import: the options from the file, then the command line's --wheel-base winning.
file(WRITE ${TD}/import.yaml "# odometry poses
image-topic: /camera/image_raw
odometry-topic: /odom
wheel-base: 0.5
odometry-k: 2.5e-5
")
run(0 ${OV} import ${FX}/ros2_zstd.mcap --out ${TD}/a --config ${TD}/import.yaml)
expect_match("${OUT}" "MCAP: 5 images \\(64x48 mono8.*21 wheel samples")
file(READ ${TD}/a/wheel0/sensor.yaml y)
expect_match("${y}" "wheel_base: 0.5 .*odometry_k: 2.5e-05")
run(0 ${OV} import ${FX}/ros2_zstd.mcap --out ${TD}/b --config ${TD}/import.yaml --wheel-base 0.7)
file(READ ${TD}/b/wheel0/sensor.yaml y)
expect_match("${y}" "wheel_base: 0.7 ")

# An unknown key (the ROS spelling of an option) and a value the option refuses.
file(WRITE ${TD}/unknown.yaml "image-topic: /camera/image_raw\n# underscores are not the option's\nwheel_base: 0.5\n")
run(2 ${OV} import ${FX}/ros2_zstd.mcap --out ${TD}/c --config ${TD}/unknown.yaml)
expect_match("${ERR}" "unknown.yaml:3: unknown key 'wheel_base': not an option of `omnivert import`")
file(WRITE ${TD}/negative.yaml "image-topic: /camera/image_raw\nwheel-base: -0.5\n")
run(2 ${OV} import ${FX}/ros2_zstd.mcap --out ${TD}/c --config ${TD}/negative.yaml)
expect_match("${ERR}" "negative.yaml:2: 'wheel-base': .*must be a number > 0, got -0.5")
file(WRITE ${TD}/flag.yaml "image-topic: /camera/image_raw\nforce: maybe\n")
run(2 ${OV} import ${FX}/ros2_zstd.mcap --out ${TD}/c --config ${TD}/flag.yaml)
expect_match("${ERR}" "flag.yaml:2: 'force': expected true or false, got maybe")
if(EXISTS ${TD}/c)
  message(FATAL_ERROR "a refused config left ${TD}/c")
endif()

# track on a recording, its options and a flag from the file; the dataset removed, then kept.
file(WRITE ${TD}/sensor.yaml "resolution: [64, 48]\ncenter: [32, 24]\nr_min: 4\nr_max: 22\n")
file(WRITE ${TD}/track.yaml "image-topic: /camera/image_raw
joint-states-topic: /joint_states
wheel-joints: [wheel_left_joint, wheel_right_joint]
wheel-radius: 0.1
wheel-base: 0.5
camera-sensor: ${TD}/sensor.yaml
no-tilt-check: true
")
run(0 ${OV} track ${FX}/ros1_lz4.bag --out ${TD}/trk --config ${TD}/track.yaml)
expect_match("${OUT}" "ROS 1 bag .*ros1_lz4.bag: 5 images \\(64x48 mono8\\), 21 wheel samples")
expect_match("${OUT}" "5 frames \\(0 skipped\\)")
if(EXISTS ${TD}/trk/dataset OR NOT EXISTS ${TD}/trk/tracks.csv)
  message(FATAL_ERROR "track on a recording: expected tracks.csv and no dataset/ in ${TD}/trk")
endif()
run(0 ${OV} track ${FX}/ros1_lz4.bag --out ${TD}/trk --config ${TD}/track.yaml --keep-dataset)
if(NOT EXISTS ${TD}/trk/dataset/cam0/data.csv)
  message(FATAL_ERROR "--keep-dataset: no ${TD}/trk/dataset")
endif()
# The same dataset folder given as it is: the recording's options are warned about.
run(0 ${OV} track ${TD}/trk/dataset --out ${TD}/trk2 --image-topic /camera/image_raw)
expect_match("${ERR}" "is a dataset folder: --image-topic \\(options of a recording\\) did nothing")

# calibrate on a recording with /tf_static: the prior named on the terminal. Five frames of a
# gradient have no lines: nothing to calibrate from (exit 2), and the imported dataset removed.
run(2 ${OV} calibrate ${FX}/ros1_description.bag --out ${TD}/cal --image-topic /camera/image_raw
    --joint-states-topic /joint_states --wheel-joints wheel_left_joint,wheel_right_joint
    --camera-sensor ${TD}/sensor.yaml)
expect_match("${OUT}" "prior: the camera's mount of /tf_static of [^\n]*ros1_description.bag \\(base_link -> omni_camera\\)")
expect_match("${ERR}" "cal/dataset: no frame has 2 or more tracked lines")
if(EXISTS ${TD}/cal/dataset)
  message(FATAL_ERROR "calibrate on a recording left ${TD}/cal/dataset")
endif()
