#!/bin/sh
# make memcheck: small runs under valgrind (memory errors, uninitialised values) and with PETSc's -malloc_debug
# -malloc_dump (PETSc memory not freed at the end). Each case is a few seconds under valgrind; the whole check a few
# minutes. Exit status 0 when every case is clean, 1 otherwise. Needs valgrind (apt-get install valgrind).
set -u
cd "$(dirname "$0")/.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_ess_singleton_isolated=1
command -v valgrind > /dev/null || { echo "memcheck: valgrind is not installed (apt-get install valgrind)" >&2; exit 2; }
out=build/memcheck
rm -rf "$out"; mkdir -p "$out"
pass=0; fail=0
# name | arguments | expected exit status
cases='cantilever_p1|-options_file options/cantilever.yaml -ts_max_steps 2 -body0_petscspace_degree 1 -body0_ic_velocity_type beam -body0_ic_velocity_direction 0,0,1|0
modes_p1|-options_file options/cantilever_modes.yaml -modes_nev 2 -body0_petscspace_degree 1|0
floating_modes|-options_file options/free_bar_modes.yaml -modes_nev 2 -body0_dm_plex_filename meshes/bar_struct_n1.msh -body0_petscspace_degree 1|0
floating_rate|-options_file options/floating_tumbling.yaml -body0_dm_plex_filename meshes/bar_struct_n2.msh -ts_max_steps 3 -output_fields 0|0
double_pendulum|-options_file options/double_pendulum.yaml -ts_max_steps 3|0
heavy_top|-options_file options/heavy_top.yaml -ts_max_steps 3|0
swinging_tip_body|-options_file tests/scenes/swinging_tip_body.yaml -ts_max_steps 2|0
fourbar_linearized|-options_file options/fourbar.yaml -linearized_sweep 0,30 -body0_dm_plex_filename meshes/fourbar_crank_nx4.msh -body1_dm_plex_filename meshes/fourbar_coupler_nx4.msh -body2_dm_plex_filename meshes/fourbar_follower_nx4.msh|0
crankslider_constant|-options_file options/crankslider.yaml -body1_inertia constant -body1_dm_plex_filename meshes/crankslider_coupler_nx8.msh -ts_max_steps 2|0
rotating_linearized|-options_file options/rotating_cantilever.yaml -body0_dm_plex_filename meshes/rotating_beam_nx8.msh -linearized_spin_sweep_range 0,360,180|0
rotating_transient|-options_file options/rotating_cantilever.yaml -analysis transient -body0_dm_plex_filename meshes/rotating_beam_nx8.msh -body0_spin 0,0,300 -ts_dt 1e-3 -ts_max_steps 2|0
checkpoint|-options_file options/flexible_double_pendulum.yaml -body0_dm_plex_filename meshes/bar_struct_n1.msh -body1_dm_plex_filename meshes/bar_struct_n1.msh -body0_petscspace_degree 1 -body1_petscspace_degree 1 -ts_max_steps 3 -output_interval 1 -checkpoint_interval 2|0
restart|-options_file options/flexible_double_pendulum.yaml -body0_dm_plex_filename meshes/bar_struct_n1.msh -body1_dm_plex_filename meshes/bar_struct_n1.msh -body0_petscspace_degree 1 -body1_petscspace_degree 1 -ts_max_steps 5 -output_interval 1 -checkpoint_interval 2 -restart build/memcheck/checkpoint/run/checkpoint.h5|0
bordered_serial|-options_file options/flexible_double_pendulum.yaml -body0_dm_plex_filename meshes/bar_struct_n1.msh -body1_dm_plex_filename meshes/bar_struct_n1.msh -body0_petscspace_degree 1 -body1_petscspace_degree 1 -ts_max_steps 2 -output_fields 0 -solver_options_file options/solver/bordered_serial.opts|0
bordered_lu_error|-options_file options/floating_tumbling.yaml -body0_dm_plex_filename meshes/bar_struct_n2.msh -ts_max_steps 2 -output_fields 0 -reduced_bordered_pc_factor_mat_solver_type cholmod|2
adaptive_retry|-options_file options/pendulum.yaml -ts_dt 2.75 -ts_max_time 6 -ts_adapt_type basic|0
series|-options_file tests/scenes/force_elements.yaml -ts_max_steps 6 -joint3_rest_length_profile_file tests/data/rest_length_ramp.csv -body0_port_tip_force 1,0,0 -body0_port_tip_profile_file tests/data/measured_load.csv -body0_port_tip_profile_column moment -output_ports block:q,arm:tip -output_ports_interval 0.0033 -checkpoint_interval 3|0
bad_series_value|-options_file options/pendulum.yaml -ts_max_time 0.1 -body0_ports pivot,tip -body0_port_tip_position 0,-1.2,0 -body0_port_tip_force 0,0,2 -body0_port_tip_profile_file tests/data/bad_value.csv -body0_port_tip_profile_column force|2
help|-help|0
help_scene|-options_file options/cantilever.yaml -help|0
misspelt_option|-options_file options/cantilever.yaml -ts_max_steps 2 -body0_petscspace_degree 1 -body0_densty 3 -ts_typ bdf|2
bad_time_step|-options_file options/cantilever.yaml -ts_dt nan|2'
echo "$cases" | while IFS='|' read -r name args expect; do
  dir="$out/$name"
  # shellcheck disable=SC2086
  valgrind -q --error-exitcode=99 --suppressions=tests/valgrind.supp bin/phlex $args -output_dir "$dir/run" -progress 0 > "$dir.valgrind.log" 2>&1
  rc=$?
  verdict=ok
  if [ "$rc" = 99 ] || grep -q "==[0-9]*== " "$dir.valgrind.log"; then verdict="valgrind errors (see $dir.valgrind.log)"
  elif [ "$rc" != "$expect" ]; then verdict="exit status $rc, expected $expect (see $dir.valgrind.log)"
  elif [ "$expect" = 0 ]; then
    rm -rf "$dir/run"
    # shellcheck disable=SC2086
    bin/phlex $args -output_dir "$dir/run" -progress 0 -malloc_debug -malloc_dump > "$dir.malloc.log" 2>&1
    if grep -q "^\[ *[0-9]*\] [0-9]* bytes" "$dir.malloc.log"; then verdict="memory not freed (see $dir.malloc.log)"; fi
  fi
  if [ "$verdict" = ok ]; then echo "ok - $name"; echo pass >> "$out/.tally"; else echo "not ok - $name: $verdict"; echo fail >> "$out/.tally"; fi
done
pass=$(grep -c pass "$out/.tally" 2>/dev/null); fail=$(grep -c fail "$out/.tally" 2>/dev/null)
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
