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
file(REMOVE_RECURSE ${DIR})
