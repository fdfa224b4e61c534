# omnivert track / evaluate as executables on a tiny simulated dataset: one real run (summary
# line, tracks.csv, tracks.png, the evaluation table and evaluation.txt) and an empty dataset
# (exit 2, the message on stderr, nothing written). What tracking finds, and damaged images,
# are asserted through the library call (tests/pipeline/track_dataset_test.cpp).
#   cmake -DOV=<omnivert> -DSRC=<12-frame dataset> -DWORK=<scratch dir> -DMODE=<mode> -P track_cli.cmake
# MODE: end_to_end | empty
cmake_minimum_required(VERSION 3.20)

function(fail msg)
  message(FATAL_ERROR "[${MODE}] ${msg}")
endfunction()

# Runs `omnivert track DATA --out OUT`; sets rc, out, err in the caller.
function(run_track data out_dir)
  execute_process(COMMAND ${OV} track ${data} --out ${out_dir}
                  RESULT_VARIABLE r OUTPUT_VARIABLE o ERROR_VARIABLE e)
  set(rc "${r}" PARENT_SCOPE)
  set(out "${o}" PARENT_SCOPE)
  set(err "${e}" PARENT_SCOPE)
endfunction()

set(data ${WORK}/${MODE})
file(REMOVE_RECURSE ${data})
file(MAKE_DIRECTORY ${data})
file(COPY ${SRC}/cam0 ${SRC}/wheel0 ${SRC}/ground_truth DESTINATION ${data})
set(out_dir ${data}/out)

if(MODE STREQUAL "end_to_end")
  run_track(${data} ${out_dir})
  if(NOT rc EQUAL 0)
    fail("track exited ${rc}: ${err}")
  endif()
  if(NOT out MATCHES "12 frames \\(0 skipped\\), [0-9]+ detections, [0-9]+ tracks")
    fail("unexpected summary: ${out}")
  endif()
  if(NOT EXISTS ${out_dir}/tracks.csv)
    fail("no tracks.csv")
  endif()
  file(STRINGS ${out_dir}/tracks.csv rows LIMIT_COUNT 1)
  if(NOT rows MATCHES "^frame,timestamp_ns,track_id,bearing_rad")
    fail("unexpected tracks.csv header: ${rows}")
  endif()
  file(SIZE ${out_dir}/tracks.png png_size)
  if(png_size LESS 1000)
    fail("tracks.png is ${png_size} bytes")
  endif()
  execute_process(COMMAND ${OV} evaluate ${data} ${out_dir}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    fail("evaluate exited ${rc}: ${err}")
  endif()
  # Total row: matches, % correct, % false matches, % false new entries, % unverified.
  if(NOT out MATCHES "Total +([0-9]+) +([0-9.]+) +([0-9.]+) +([0-9.]+) +([0-9.]+)")
    fail("no Total row in: ${out}")
  endif()
  if(NOT out MATCHES "Bearing RMS error: ")
    fail("no bearing RMS in: ${out}")
  endif()
  if(NOT EXISTS ${out_dir}/evaluation.txt)
    fail("no evaluation.txt")
  endif()

elseif(MODE STREQUAL "empty")
  file(WRITE ${data}/cam0/data.csv "#timestamp [ns],filename\n")
  run_track(${data} ${out_dir})
  if(NOT rc EQUAL 2)
    fail("expected exit code 2, got ${rc}")
  endif()
  if(NOT err MATCHES "omnivert: error: [^\n]*cam0/data.csv: no images listed")
    fail("expected an error naming cam0/data.csv, stderr: ${err}")
  endif()
  if(EXISTS ${out_dir}/tracks.csv)
    fail("an empty dataset left a tracks.csv")
  endif()

else()
  fail("unknown MODE")
endif()
