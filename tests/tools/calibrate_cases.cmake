# Rendered runs where calibration once failed, each calibrated from pixels (no --refine) and
# checked against its ground truth (summary.json). CASE names the run.
#
# The filter's batch window solved from several starts (calib::CalibrationOptions::
# filter.bootstrap_starts, docs/theory/window.md#starts), CASE prior and flow:
# - prior: the office, zigzag, seed 11 run, whose window solved from the prior alone ends in a
#   local minimum (measured before the fix: camera yaw 2.0 degrees off, NEES 9175);
# - flow: the corridor, zigzag, seed 57 run with the camera mounted at -107.5 degrees of yaw
#   (phi -0.915, psi -0.961 rad: scripts/eval-calibration's VARY_EXTRINSICS draw for seed 57),
#   where every start at the prior's camera yaw ended far off and the filter 33 degrees off in
#   phi (NEES 1e10) before the starts at the bearings' flow yaw (calib::camera_yaw_from_flow).
# Each must end near the truth.
#
# The filter's crossing guard (calib::CalibrationOptions::association.crossing_guard), CASE
# start and window: office, paper trajectory, each with the camera mount
# scripts/eval-calibration's VARY_EXTRINSICS draws for its seed.
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
if(CASE STREQUAL "flow")
  set(sim --world corridor --trajectory zigzag --seed 57 --phi -0.9148685728348462
          --rho 0.21793729008033075 --psi -0.961378377305627)
elseif(CASE STREQUAL "prior")
  set(sim --world office --trajectory zigzag --seed 11)
elseif(CASE STREQUAL "start")
  set(sim --world office --trajectory paper --seed 32 --phi -0.8451564322933918
          --rho 0.14272335789299767 --psi -0.39374332579442917)
elseif(CASE STREQUAL "window")
  set(sim --world office --trajectory paper --seed 36 --phi -0.3425989589338041
          --rho 0.2966427833152556 --psi 0.918495070954692)
else()
  message(FATAL_ERROR "unknown CASE '${CASE}'")
endif()
execute_process(COMMAND ${OV} simulate ${sim} --out ${WORK}/data --force
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
string(JSON yaw GET "${js}" errors_vs_ground_truth filter yaw_deg)
string(JSON pos GET "${js}" errors_vs_ground_truth filter position_mm)
string(JSON psi GET "${js}" errors_vs_ground_truth filter psi_deg)
string(JSON rho GET "${js}" errors_vs_ground_truth filter rho_mm)
string(JSON nees GET "${js}" errors_vs_ground_truth filter nees)
string(JSON guarded GET "${js}" filter bearings_guarded)
string(JSON crlb GET "${js}" observability psi crlb)
message(STATUS "filter: camera yaw error ${yaw} deg, position error ${pos} mm, psi error ${psi} "
               "deg, rho error ${rho} mm, NEES ${nees}, psi bound ${crlb} rad, ${guarded} "
               "bearings guarded")
if(CASE STREQUAL "prior" OR CASE STREQUAL "flow")
  if(yaw GREATER 0.5 OR yaw LESS -0.5 OR pos GREATER 5)
    message(FATAL_ERROR "the filter ended off: camera yaw error ${yaw} deg, position error ${pos} mm")
  endif()
elseif(CASE STREQUAL "window")
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
