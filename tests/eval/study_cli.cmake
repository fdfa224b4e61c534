# omnivert study end to end on a tiny simulated dataset: every subcommand runs and writes its
# files. Usage: cmake -DOV=omnivert -DDIR=work_dir -P study_cli.cmake
file(REMOVE_RECURSE ${DIR})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()
run(${OV} simulate --world corridor --trajectory paper --frames 5 --out ${DIR}/run)
file(GLOB images ${DIR}/run/cam0/data/*.png)
list(GET images 0 first)
run(${OV} study similarity ${first} --sensor ${DIR}/run/cam0/sensor.yaml --steps 90 --out ${DIR}/sim)
run(${OV} study sensitivity ${DIR}/run --out ${DIR}/sens)
run(${OV} study baselines ${DIR}/run --out ${DIR}/base)
foreach(f sim/similarity_descriptor.png sim/similarity_ssd.png sim/similarity_zncc.png sim/panorama.png
          sim/similarity_summary.csv sim/similarity_zncc.csv
          sens/sensitivity_clip.csv sens/sensitivity_clip.png sens/sensitivity_noise.png sens/sensitivity_bins.png
          sens/rule1_pdf.png sens/rule2_pdf.csv sens/rule3_pdf.png sens/rules.csv
          base/baselines.csv base/baselines_pr.csv base/baselines_pr.png)
  if(NOT EXISTS ${DIR}/${f})
    message(FATAL_ERROR "missing output ${DIR}/${f}")
  endif()
endforeach()
file(STRINGS ${DIR}/base/baselines.csv rows)
list(LENGTH rows n)
if(NOT n EQUAL 7)  # header, 5 methods, the three-rule operating point
  message(FATAL_ERROR "baselines.csv has ${n} rows:\n${rows}")
endif()
file(STRINGS ${DIR}/sens/sensitivity_clip.csv rows)
list(LENGTH rows n)
if(NOT n EQUAL 11)  # header and ten thresholds
  message(FATAL_ERROR "sensitivity_clip.csv has ${n} rows")
endif()
file(GLOB_RECURSE csvs ${DIR}/*.csv)
foreach(f ${csvs})
  if(f MATCHES "/run/")
    continue()
  endif()
  file(READ ${f} text)
  string(TOLOWER "${text}" text)
  if(text MATCHES "nan|inf")
    message(FATAL_ERROR "${f} holds nan or inf")
  endif()
endforeach()

# Bad input: a dataset without ground-truth lines is exit code 2 with the file named.
file(REMOVE ${DIR}/run/ground_truth/lines.csv)
execute_process(COMMAND ${OV} study sensitivity ${DIR}/run --out ${DIR}/bad RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 2 OR NOT err MATCHES "lines.csv")
  message(FATAL_ERROR "expected exit 2 naming lines.csv, got ${rc}: ${err}")
endif()
file(REMOVE_RECURSE ${DIR})
