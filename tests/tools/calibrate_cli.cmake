# omnivert calibrate as an executable, on a tiny simulated dataset (12 frames of the paper's
# trajectory, which has not turned yet): the exit code and message of an undetermined run,
# what only the command line does (--prior FILE, the note on extraction flags given with
# --tracks), and a bad prior file. The main job's results are asserted through the library
# call (tests/pipeline).
#   cmake -DOV=<omnivert> -DDATA=<12-frame dataset> -DWORK=<scratch dir> -DMODE=<mode> -P calibrate_cli.cmake
# MODE: undetermined | forced | bad_prior | dataset_prior
cmake_minimum_required(VERSION 3.20)

function(fail msg)
  message(FATAL_ERROR "[${MODE}] ${msg}")
endfunction()

# Runs `omnivert calibrate DATA --out OUT ARGN`; sets rc, out, err in the caller.
function(run_calibrate out_dir)
  execute_process(COMMAND ${OV} calibrate ${DATA} --out ${out_dir} ${ARGN}
                  RESULT_VARIABLE r OUTPUT_VARIABLE o ERROR_VARIABLE e)
  set(rc "${r}" PARENT_SCOPE)
  set(out "${o}" PARENT_SCOPE)
  set(err "${e}" PARENT_SCOPE)
endfunction()

set(out_dir ${WORK}/${MODE}-out)
file(REMOVE_RECURSE ${out_dir})
file(MAKE_DIRECTORY ${WORK})

if(MODE STREQUAL "undetermined")
  # Exit 3, no extrinsics.yaml, a message saying what is not determined and the motion that
  # fixes it; the other outputs are written.
  run_calibrate(${out_dir})
  if(NOT rc EQUAL 3)
    fail("an undetermined run must exit 3, exited ${rc}: ${err}")
  endif()
  if(NOT err MATCHES "omnivert: the extrinsics are not determined by this run" OR NOT err MATCHES "turn"
     OR NOT err MATCHES "--force writes it anyway")
    fail("the message must say what is not determined and the motion that fixes it: ${err}")
  endif()
  if(EXISTS ${out_dir}/extrinsics.yaml OR NOT EXISTS ${out_dir}/summary.json)
    fail("expected summary.json and no extrinsics.yaml")
  endif()
  if(NOT out MATCHES "results in ")
    fail("stdout lacks the brief report: ${out}")
  endif()

elseif(MODE STREQUAL "forced")
  # --force: exit 0 and extrinsics.yaml; --prior FILE (an extrinsics.yaml-like file) is the
  # prior of the summary; --tracks with an extraction flag says the flag did nothing.
  file(WRITE ${WORK}/prior.yaml "phi: -0.3\nrho: 0.25\npsi: 0.3\nsigma_phi: 0.2\nsigma_rho: 0.05\nsigma_psi: 0.2\n")
  run_calibrate(${out_dir} --force --prior ${WORK}/prior.yaml)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${out_dir}/extrinsics.yaml)
    fail("--force must exit 0 and write extrinsics.yaml, exited ${rc}: ${err}")
  endif()
  file(READ ${out_dir}/summary.json json)
  string(JSON p GET "${json}" inputs prior rho)
  string(JSON s GET "${json}" inputs prior sigma_rho)
  if(NOT p EQUAL 0.25 OR NOT s EQUAL 0.05)
    fail("prior rho and its sigma from the file: ${p}, ${s}")
  endif()
  run_calibrate(${out_dir} --force --tracks ${out_dir}/tracks.csv --length-fraction 0.3)
  if(NOT rc EQUAL 0 OR NOT EXISTS ${out_dir}/tracks.csv)
    fail("--tracks DIR/tracks.csv --out DIR exited ${rc}: ${err}")
  endif()
  if(NOT err MATCHES "--tracks: the tracks are read from .*; --length-fraction \\(extraction and tracking options\\) did nothing")
    fail("--tracks with an extraction flag should say the flag did nothing: ${err}")
  endif()

elseif(MODE STREQUAL "bad_prior")
  # A bad value in the prior file: exit 2 naming file, line and field; nothing written.
  file(WRITE ${WORK}/prior-bad.yaml "phi: 0\nrho: far\n")
  run_calibrate(${out_dir} --prior ${WORK}/prior-bad.yaml)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "omnivert: error: [^\n]*prior-bad.yaml:2: field 'rho' must be a number, got 'far'")
    fail("expected exit 2 naming prior-bad.yaml line 2, got ${rc}: ${err}")
  endif()
  if(EXISTS ${out_dir}/summary.json)
    fail("a bad prior file left a summary.json")
  endif()

elseif(MODE STREQUAL "dataset_prior")
  # The dataset's prior.yaml (as the import writes it from a recording's /tf_static): the
  # prior's mean, its source in summary.json and report.html, its frames and height in the
  # robot formats; the flags override its mean.
  file(REMOVE_RECURSE ${WORK}/prior-data)
  file(COPY ${DATA}/ DESTINATION ${WORK}/prior-data)
  file(WRITE ${WORK}/prior-data/prior.yaml "source: \"/tf_static of run.bag (base_link -> omni_camera)\"
base_frame: base_link
camera_frame: omni_camera
phi: 0.1
rho: 0.25
psi: -0.2
camera_height: 0.35
")
  set(DATA ${WORK}/prior-data)
  run_calibrate(${out_dir} --force)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "prior: the camera's mount of /tf_static of run.bag \\(base_link -> omni_camera\\)")
    fail("expected the prior's source on the terminal, got ${rc}: ${out} ${err}")
  endif()
  file(READ ${out_dir}/summary.json j)
  string(JSON phi GET "${j}" inputs prior phi)
  string(JSON rho GET "${j}" inputs prior rho)
  string(JSON source GET "${j}" inputs prior source)
  if(NOT phi EQUAL 0.1 OR NOT rho EQUAL 0.25 OR NOT source STREQUAL "/tf_static of run.bag (base_link -> omni_camera)")
    fail("summary.json's prior: phi ${phi}, rho ${rho}, source '${source}'")
  endif()
  file(READ ${out_dir}/report.html html)
  file(READ ${out_dir}/camera_joint.urdf urdf)
  if(NOT html MATCHES "prior \\(/tf_static of run.bag \\(base_link -&gt; omni_camera\\)\\)" OR
     NOT urdf MATCHES "<child link=\"omni_camera\"/>" OR NOT urdf MATCHES "xyz=\"[^ ]+ [^ ]+ 0.35\"")
    fail("the report must name the prior, the URDF its frame and height:\n${urdf}")
  endif()
  run_calibrate(${out_dir} --force --phi 0.3)
  file(READ ${out_dir}/summary.json j)
  string(JSON phi GET "${j}" inputs prior phi)
  string(JSON source GET "${j}" inputs prior source)
  if(NOT phi EQUAL 0.3 OR NOT source MATCHES ", then the flags$")
    fail("--phi must override prior.yaml: phi ${phi}, source '${source}'")
  endif()

else()
  fail("unknown MODE")
endif()
