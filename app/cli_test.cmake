# End-to-end checks of the `nebula` command line (run by ctest with
# -DNEBULA=<binary> -DWORK=<scratch folder>).
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

# expect_failure(NAME NEEDLE ARGS...): non-zero exit, a one-line error that
# contains NEEDLE, and no table written.
function(expect_failure name needle)
  execute_process(COMMAND ${NEBULA} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  WORKING_DIRECTORY ${WORK})
  if(rc EQUAL 0)
    message(FATAL_ERROR "${name}: expected failure, got exit 0")
  endif()
  string(STRIP "${err}" err)
  string(FIND "${err}" "${needle}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${name}: error does not mention '${needle}': ${err}")
  endif()
  string(FIND "${err}" "\n" newline)
  if(NOT newline EQUAL -1)
    message(FATAL_ERROR "${name}: error spans several lines: ${err}")
  endif()
  file(GLOB leftovers ${WORK}/bad*)
  if(leftovers)
    message(FATAL_ERROR "${name}: left files behind: ${leftovers}")
  endif()
endfunction()

set(small --tau-bins 3 --mu-bins 8 --photons 2000 --backend cpu -q)
expect_failure(albedo "--albedo" tabulate --albedo 1.5 ${small} -o bad.h5)
expect_failure(g_one "--g" tabulate --g 1 ${small} -o bad.h5)
expect_failure(g_minus_one "--g" tabulate --g -1 ${small} -o bad.h5)
expect_failure(tau "--tau-max" tabulate --tau-max -2 ${small} -o bad.h5)
expect_failure(bins "--mu-bins" tabulate --tau-bins 3 --mu-bins 1 --photons 100 -o bad.h5)
expect_failure(tau_bins "--tau-bins" tabulate --tau-bins 1 --photons 100 -o bad.h5)
expect_failure(photons_zero "--photons" tabulate --tau-bins 3 --photons 0 -o bad.h5)
expect_failure(photons_text "--photons" tabulate --tau-bins 3 --photons lots -o bad.h5)
expect_failure(binning "--binning" tabulate ${small} --binning log -o bad.h5)
expect_failure(unwritable "folder" tabulate ${small} -o ${WORK}/no/such/dir/bad.h5)
expect_failure(slab_tau "--tau" slab --albedo 0.5 --g 0 --tau 0 --backend cpu)
expect_failure(slab_albedo "--albedo" slab --albedo -0.1 --g 0 --tau 1 --backend cpu)
expect_failure(missing_table "missing.h5" table info missing.h5)
file(WRITE ${WORK}/text.h5 "not a table\n")
expect_failure(text_table "text.h5" table info text.h5)

# Rendering: bad requests fail before any work, with one line.
set(ENV{NEBULA_CACHE_DIR} ${WORK}/cache)
expect_failure(render_nothing "--demo" render -o bad.png)
expect_failure(render_demo_set "--set" render --demo --set camera.fov_deg=30 -o bad.png)
expect_failure(render_extension "unknown image extension" render --demo -o bad.jpg)
file(WRITE ${WORK}/scene_with_typo.toml
     "[density]\nprocedural = { n = 8 }\n[[stars]]\nluminosity_lsun = 1.0\nclass = \"G2V\"\n[camera]\nzoom = 3\n")
expect_failure(render_unknown_key "camera.zoom" render scene_with_typo.toml -o bad.h5)
expect_failure(render_missing_scene "missing.toml" render missing.toml -o bad.h5)
expect_failure(render_levels_negative "--levels" render --demo --levels -2 -o bad.h5)
expect_failure(render_levels_too_many "--levels: 9 exceeds the 6" render --demo --levels 9 -o bad.h5)
file(WRITE ${WORK}/scene_levels.toml
     "[density]\nprocedural = { n = 8 }\n[[stars]]\nluminosity_lsun = 1.0\nclass = \"G2V\"\n[camera]\n"
     "position = [0.5, -3, 1]\nlook_at = [1, 1, 1]\n[render]\nlevels = 3\n")
expect_failure(render_levels_scene "render.levels: 3 exceeds the 2" render scene_levels.toml -o bad.h5)
# A small real render (tables generated into the scratch cache).
execute_process(COMMAND ${NEBULA} render ${SOURCE}/scenes/uniform_sphere.toml --width 24 --height 24
                        --table-photons 2000 --backend cpu -q --levels 2 -o sphere.h5
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/sphere.h5)
  message(FATAL_ERROR "render failed (${rc}): ${out} ${err}")
endif()
string(FIND "${out}" "computed, and why" at)
string(FIND "${out}" "pyramid level 2:" level_at)
if(at EQUAL -1 OR level_at EQUAL -1)
  message(FATAL_ERROR "render printed no account of what it computed (and its 2 pyramid levels): ${out}")
endif()

# --set takes one value each time: a scene file after it is the scene, not another override.
execute_process(COMMAND ${NEBULA} render --set dust.g=0.8 ${SOURCE}/scenes/uniform_sphere.toml --width 8 --height 8
                        --table-photons 2000 --backend cpu -q -o set_first.h5
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
string(FIND "${out}" "g 0.8" at)
if(NOT rc EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "render --set KEY=VALUE SCENE failed (${rc}): ${out} ${err}")
endif()
# An unknown command is named, with the nearest known one.
expect_failure(unknown_command "'rendr' is not a command; did you mean 'render'?" rendr scene.toml)
expect_failure(unknown_far_command "'paint' is not a command (commands: render, truth" paint)

# The ground truth and the comparison: bad requests fail before any work, with one line.
set(sphere ${SOURCE}/scenes/uniform_sphere.toml)
expect_failure(truth_no_spp "--spp" truth ${sphere} -o bad.h5)
expect_failure(truth_spp_one "--spp" truth ${sphere} --spp 1 -o bad.h5)
expect_failure(truth_spp_text "--spp" truth ${sphere} --spp many -o bad.h5)
expect_failure(truth_extension "unknown image extension" truth ${sphere} --spp 4 -o bad.jpg)
expect_failure(truth_orders "--max-orders" truth ${sphere} --spp 4 --max-orders -1 -o bad.h5)
expect_failure(truth_block "--majorant-block" truth ${sphere} --spp 4 --majorant-block 0 -o bad.h5)
expect_failure(truth_missing_scene "missing.toml" truth missing.toml --spp 4 -o bad.h5)
expect_failure(truth_unknown_key "camera.zoom" truth scene_with_typo.toml --spp 4 -o bad.h5)
expect_failure(truth_backend "--backend" truth ${sphere} --spp 4 --backend tpu -o bad.h5)
expect_failure(truth_transmittance "--transmittance" truth ${sphere} --spp 4 --transmittance guess -o bad.h5)
expect_failure(bench_truth_spp "--spp" bench truth --backend cpu --spp 1)
expect_failure(bench_truth_transmittance "--transmittance" bench truth --backend cpu --transmittance guess)
execute_process(COMMAND ${NEBULA} truth ${sphere} --spp 4 --width 12 --height 10 --backend cpu -q -o truth.h5
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/truth.h5 OR NOT EXISTS ${WORK}/truth.var.h5)
  message(FATAL_ERROR "truth failed (${rc}): ${out} ${err}")
endif()
expect_failure(truth_exists "--force" truth ${sphere} --spp 4 --width 12 --height 10 --backend cpu -q -o truth.h5)
expect_failure(compare_missing "missing.h5" compare missing.h5 truth.h5)
expect_failure(compare_size "sphere.h5" compare sphere.h5 truth.h5)
expect_failure(compare_diff_format "--diff" compare truth.h5 truth.h5 --diff bad.jpg)
expect_failure(compare_signal "--signal" compare truth.h5 truth.h5 --signal 2)
execute_process(COMMAND ${NEBULA} compare truth.h5 truth.h5 --json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
foreach(key rel_l1 rel_l2 worst_1pct bias within_noise noise_rel_l2)
  string(FIND "${out}" "\"${key}\":" at)
  if(NOT rc EQUAL 0 OR at EQUAL -1)
    message(FATAL_ERROR "compare --json lacks ${key} (${rc}): ${out} ${err}")
  endif()
endforeach()

# A good run, then the overwrite rule.
execute_process(COMMAND ${NEBULA} tabulate ${small} -o good.h5 RESULT_VARIABLE rc OUTPUT_VARIABLE out
                WORKING_DIRECTORY ${WORK})
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/good.h5)
  message(FATAL_ERROR "tabulate failed (${rc}): ${out}")
endif()
expect_failure(overwrite "--force" tabulate ${small} -o good.h5)
execute_process(COMMAND ${NEBULA} tabulate ${small} --force -o good.h5 RESULT_VARIABLE rc
                WORKING_DIRECTORY ${WORK})
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "tabulate --force failed")
endif()
execute_process(COMMAND ${NEBULA} table info good.h5 RESULT_VARIABLE rc OUTPUT_VARIABLE out
                WORKING_DIRECTORY ${WORK})
string(FIND "${out}" "albedo 0.6" at)
if(NOT rc EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "table info failed (${rc}): ${out}")
endif()
execute_process(COMMAND ${NEBULA} slab --albedo 0.9 --g 0.75 --tau 2 --photons 1e4 --backend cpu --json
                RESULT_VARIABLE rc OUTPUT_VARIABLE out)
foreach(key R_diffuse R_stderr T_total T_stderr T_unscattered)
  string(FIND "${out}" "\"${key}\":" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "slab --json lacks ${key}: ${out}")
  endif()
endforeach()
file(GLOB temps ${WORK}/*.tmp*)
if(temps)
  message(FATAL_ERROR "temporary files left: ${temps}")
endif()

# Axial maps: a synthetic map rendered to a float image, that image read back
# as a map (tau_v from its V channel, emission from B), the benchmark, refusals.
file(WRITE ${WORK}/axial.toml "bands = [\"B\", \"V\"]\n[axial]\nsynthetic = \"lopsided\"\nnx = 32\nnr = 16\nemission_scale = 1.0\n[camera]\nkind = \"orthographic\"\nposition = [4.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 1.0]\northo_width = 4.0\nwidth = 24\nheight = 24\n")
execute_process(COMMAND ${NEBULA} render axial.toml -o axial_map.h5 --backend cpu -q RESULT_VARIABLE rc OUTPUT_VARIABLE out
                ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/axial_map.h5)
  message(FATAL_ERROR "axial render failed (${rc}): ${out} ${err}")
endif()
file(WRITE ${WORK}/axial_image.toml "bands = [\"B\", \"V\"]\n[axial]\nimage = \"axial_map.h5\"\ntau_channel = \"V\"\nemission_channels = { B = \"B\" }\ntau_scale = 10.0\n[camera]\nposition = [0.0, -5.0, 1.0]\nlook_at = [0.0, 0.0, 1.0]\nwidth = 16\nheight = 16\n")
execute_process(COMMAND ${NEBULA} render axial_image.toml -o axial_image.h5 --backend cpu -q RESULT_VARIABLE rc
                OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
string(FIND "${out}" "axial map 24x24" at)
if(NOT rc EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "axial render from an image map failed (${rc}): ${out} ${err}")
endif()
expect_failure(axial_skip "axial.skip" render axial.toml --set axial.skip=fast -o bad.h5)
expect_failure(axial_channel "axial.tau_channel" render axial_image.toml --set axial.tau_channel=X -o bad.h5)
expect_failure(axial_smooth "--smooth" render axial.toml --smooth 0.5 -o bad.h5)
expect_failure(bench_axial_map "--maps" bench axial --backend cpu --maps spiral)
execute_process(COMMAND ${NEBULA} bench axial --backend cpu --map-size 16 --image 16 --repeats 1 --inclinations 0,90
                        --maps bipolar,shells,full --emission-only
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(FIND "${out}" "| full | 0.0% | yes | 90 | omega_multi | naive |" at)
string(FIND "${out}" "| thesis_omega_multi | 5.3x | 6.3x |" tables)
if(NOT rc EQUAL 0 OR at EQUAL -1 OR tables EQUAL -1)
  message(FATAL_ERROR "bench axial failed (${rc}): ${out} ${err}")
endif()

# Sweeps: a 2 x 2 albedo x g grid to a FITS cube (its shape and axes read back
# by `nebula sweep` itself is not enough: python.module checks the pixels),
# and the refusals, each before any work and with nothing written.
file(WRITE ${WORK}/sweep.toml "[density]\nprocedural = { n = 12, size_pc = 2.0 }\n[[stars]]\nluminosity_lsun = 2e5\nclass = \"O5V\"\n[camera]\nposition = [1.0, -2.5, 1.0]\nlook_at = [1.0, 1.0, 1.0]\nwidth = 12\nheight = 10\n[render]\ndiffuse_photons = 16384\n")
execute_process(COMMAND ${NEBULA} sweep sweep.toml --grid dust.albedo=0.3:0.9:2 --grid dust.g=0,0.6 -o sweep.fits
                        --backend cpu --table-photons 1000 -q
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
string(FIND "${out}" "sweep: 4 points (dust.albedo x 2, dust.g x 2)" at)
string(FIND "${out}" "star bakes 3 of 4" reused)
if(NOT rc EQUAL 0 OR at EQUAL -1 OR reused EQUAL -1 OR NOT EXISTS ${WORK}/sweep.fits)
  message(FATAL_ERROR "sweep failed (${rc}): ${out} ${err}")
endif()
set(sweep_ok sweep.toml --backend cpu --table-photons 1000 -q)
expect_failure(sweep_key "dust.albdo" sweep ${sweep_ok} --grid dust.albdo=0.3,0.6 -o bad.fits)
expect_failure(sweep_value "dust.albedo" sweep ${sweep_ok} --grid dust.albedo=0.3,1.5 -o bad.fits)
expect_failure(sweep_empty "empty range" sweep ${sweep_ok} --grid dust.albedo=0.3:0.9:0 -o bad.fits)
expect_failure(sweep_text "'x' is not a number" sweep ${sweep_ok} --grid dust.g=0,x -o bad.fits)
expect_failure(sweep_form "KEY=START:STOP:COUNT" sweep ${sweep_ok} --grid dust.g -o bad.fits)
expect_failure(sweep_twice "swept twice" sweep ${sweep_ok} --grid dust.g=0 --grid dust.g=0.3 -o bad.fits)
expect_failure(sweep_large "--force" sweep ${sweep_ok} --grid dust.g=0:0.5:1000 --grid dust.albedo=0:1:1000 -o bad.fits)
expect_failure(sweep_png "a cube is written as" sweep ${sweep_ok} --grid dust.g=0 -o bad.png)
