# The filter's crossing guard (calib::Options::crossing_guard) on two rendered runs where it
# failed before (office, paper trajectory, each with the camera mount scripts/
# eval-calibration's VARY_EXTRINSICS draws for its seed). Reads summary.json: the errors
# against the ground truth, the bound of the filter's problem and the bearings it guarded.
# - CASE=start, seed 32: a line's track starts at frame 80 0.5 degree from a line tracked over
#   the whole run, and the two part to 1.1 degree. Judged by the predictions alone, the new
#   feature (depth unknown) was guarded from its start, never updated, and kept guarding the
#   long line to the end: 57 bearings left out instead of 39, the bound of the filter's
#   problem for psi 0.37 degree instead of 0.22, its psi error -0.82 degree (-0.36 now; the
#   refinement's -0.40). The guard now judges a feature seen in the frame by its bearing.
# - CASE=window, seed 36: a line's last two bearings in the start-up window were pushed 0.09-
#   0.12 degree by a line whose track started two frames after the window; with them, the
#   filter ended 2.6 mm off in rho, NEES 19.4; left out (guard_before_starts, in the window
#   for tracks that start after it), 2.1 mm, NEES 10.4 (the refinement's: 1.2 mm, 12.2).
if(CASE STREQUAL "window")
  set(sim --seed 36 --phi -0.3425989589338041 --rho 0.2966427833152556
          --psi 0.918495070954692)
else()
  set(sim --seed 32 --phi -0.8451564322933918 --rho 0.14272335789299767
          --psi -0.39374332579442917)
endif()
execute_process(COMMAND ${OV} simulate --world office --trajectory paper ${sim}
                        --out ${WORK}/data --force
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
string(JSON rho GET "${js}" errors_vs_ground_truth filter rho_mm)
string(JSON nees GET "${js}" errors_vs_ground_truth filter nees)
string(JSON guarded GET "${js}" filter bearings_guarded)
string(JSON crlb GET "${js}" observability psi crlb)
message(STATUS "filter: psi error ${psi} deg, rho error ${rho} mm, NEES ${nees}, psi bound "
               "${crlb} rad, ${guarded} bearings guarded")
if(CASE STREQUAL "window")
  if(nees GREATER 14 OR rho LESS -2.4)
    message(FATAL_ERROR "the filter's NEES is ${nees}, its rho ${rho} mm off (measured 10.4, "
                        "-2.08; 19.4, -2.64 with the window's tail kept)")
  endif()
else()
  if(psi GREATER 0.55 OR psi LESS -0.55)
    message(FATAL_ERROR "the filter's psi is ${psi} deg off (measured -0.36; -0.82 with the "
                        "guard on predictions)")
  endif()
  if(crlb GREATER 0.0047)  # 0.27 degree
    message(FATAL_ERROR "the filter's problem lost bearings: psi bound ${crlb} rad (measured "
                        "0.0039; 0.0064 with the guard on predictions)")
  endif()
  if(guarded GREATER 48)
    message(FATAL_ERROR "${guarded} bearings guarded (measured 39; 57 with the guard on "
                        "predictions)")
  endif()
endif()
