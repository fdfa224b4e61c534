# The filter's crossing guard (calib::Options::crossing_guard) judges a feature measured in the
# frame by its bearing, not by the state's prediction, and lets a track that starts beside
# another line enter at its first bearing outside the guard. The run: office, paper
# trajectory, seed 32, camera mounted at phi -0.845, rho 0.143, psi -0.394 (scripts/
# eval-calibration's VARY_EXTRINSICS draw for seed 32). A line's track starts at frame 80 0.5
# degree from a line tracked over the whole run, and the two part to 1.1 degree. Judged by the
# predictions, the new feature (depth unknown) was guarded from its start, never updated, and
# kept guarding the long line to the end: 57 bearings left out instead of 39, the bound of the
# filter's problem for psi 0.37 degree instead of 0.22, its psi error -0.82 degree (-0.36 now;
# the refinement's -0.40). Reads summary.json: the errors against the ground truth and the bound.
execute_process(COMMAND ${OV} simulate --world office --trajectory paper --seed 32
                        --phi -0.8451564322933918 --rho 0.14272335789299767
                        --psi -0.39374332579442917 --out ${WORK}/data --force
                RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "simulate: exit ${rc}: ${err}")
endif()
execute_process(COMMAND ${OV} calibrate ${WORK}/data --out ${WORK}/run --force
                RESULT_VARIABLE rc OUTPUT_QUIET ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "calibrate: exit ${rc}: ${err}")
endif()
file(READ ${WORK}/run/summary.json js)
string(JSON psi GET "${js}" errors_vs_ground_truth filter psi_deg)
string(JSON guarded GET "${js}" filter bearings_guarded)
string(JSON crlb GET "${js}" observability psi crlb)
message(STATUS "filter: psi error ${psi} deg, psi bound ${crlb} rad, ${guarded} bearings guarded")
if(psi GREATER 0.55 OR psi LESS -0.55)
  message(FATAL_ERROR "the filter's psi is ${psi} deg off (measured -0.36; -0.82 with the guard on predictions)")
endif()
if(crlb GREATER 0.0047)  # 0.27 degree
  message(FATAL_ERROR "the filter's problem lost bearings: psi bound ${crlb} rad (measured 0.0039; 0.0064 with the guard on predictions)")
endif()
if(guarded GREATER 48)
  message(FATAL_ERROR "${guarded} bearings guarded (measured 39; 57 with the guard on predictions)")
endif()
