# End-to-end checks of issue 17 ("Reliability") on the `nebula` command line
# (run by ctest with -DNEBULA=<binary> -DWORK=<scratch folder> -DSOURCE=<tree>):
# outputs never overwrite inputs, values are refused up front naming their
# option or key, and memory is estimated before anything is allocated.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(ENV{NEBULA_CACHE_DIR} ${WORK}/cache)

# run(NAME ARGS...): sets rc, out and err of `nebula ARGS` in WORK.
macro(run)
  execute_process(COMMAND ${NEBULA} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  WORKING_DIRECTORY ${WORK})
  string(STRIP "${err}" err)
endmacro()

# refused(NAME NEEDLE ARGS...): exit 1 (a user error, not an internal one),
# one line on stderr containing NEEDLE.
function(refused name needle)
  run(${ARGN})
  if(NOT rc EQUAL 1)
    message(FATAL_ERROR "${name}: expected exit 1, got ${rc}: ${err}")
  endif()
  string(FIND "${err}" "${needle}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "${name}: error does not mention '${needle}': ${err}")
  endif()
  string(FIND "${err}" "\n" newline)
  if(NOT newline EQUAL -1)
    message(FATAL_ERROR "${name}: error spans several lines: ${err}")
  endif()
endfunction()

set(small --tau-bins 3 --mu-bins 8 --photons 2000 --backend cpu -q)
set(star "[[stars]]\nluminosity_lsun = 1.0\nclass = \"G2V\"\n")
set(camera "[camera]\nposition = [0.5, -3, 0.5]\nlook_at = [0.5, 0.5, 0.5]\nwidth = 8\nheight = 8\n")

# Item 2: -o never names an input, whatever its name and with or without --force.
run(tabulate ${small} -o table.h5)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "tabulate failed (${rc}): ${err}")
endif()
file(SHA256 ${WORK}/table.h5 table_before)
file(WRITE ${WORK}/with_table.toml "[density]\nprocedural = { n = 8 }\n${star}${camera}[dust.tables]\nV = \"table.h5\"\n")
refused(output_is_table "dust.tables.V" render with_table.toml -o table.h5 --force -q --backend cpu)
file(CREATE_LINK ${WORK}/table.h5 ${WORK}/linked.h5)
refused(output_is_table_other_name "dust.tables.V" render with_table.toml -o linked.h5 --force -q --backend cpu)
file(SHA256 ${WORK}/table.h5 table_after)
if(NOT table_before STREQUAL table_after)
  message(FATAL_ERROR "output_is_table: the table file was changed")
endif()

# Item 7: a table named by the scene that cannot be read is blamed on its key.
file(WRITE ${WORK}/broken_table.h5 "not a table\n")
file(WRITE ${WORK}/with_broken_table.toml "[density]\nprocedural = { n = 8 }\n${star}${camera}[dust.tables]\nV = \"broken_table.h5\"\n")
refused(table_key "with_broken_table.toml: dust.tables.V: " render with_broken_table.toml -o out.h5 -q --backend cpu)

# Item 7: --backend gpu is called gpu (on a machine without one; with one it renders).
file(WRITE ${WORK}/small.toml "[density]\nprocedural = { n = 8 }\n${star}${camera}")
run(render small.toml -o gpu.h5 -q --backend gpu --table-photons 2000)
if(NOT rc EQUAL 0)
  string(FIND "${err}" "--backend: gpu requested" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "backend_gpu: the error does not echo 'gpu': ${err}")
  endif()
endif()

# Item 6: values whose consequences were not checked are refused up front.
refused(width_zero "--width: is 0" render small.toml -o out.h5 -q --backend cpu --width 0)
refused(height_zero "--height: is 0" render small.toml -o out.h5 -q --backend cpu --height 0)
refused(smooth_inf "--smooth" render small.toml -o out.h5 -q --backend cpu --smooth inf)
refused(luminosity "stars.0.luminosity_lsun" render small.toml -o out.h5 -q --backend cpu --set stars.0.luminosity_lsun=1e300)
refused(exposure "camera.exposure" render small.toml -o out.h5 -q --backend cpu --set camera.exposure=1e38)
file(WRITE ${WORK}/axial.toml "bands = [\"V\"]\n[axial]\nsynthetic = \"shells\"\nnx = 16\nnr = 8\n[[stars]]\nposition = [0, 0, 1]\nluminosity_lsun = 1.0\nclass = \"G2V\"\n[camera]\nposition = [4.0, 0.0, 1.0]\nlook_at = [0.0, 0.0, 1.0]\nwidth = 8\nheight = 8\n")
refused(step_texels "axial.step_texels" render axial.toml -o out.h5 -q --backend cpu --table-photons 2000 --set axial.step_texels=1e30)
if(EXISTS ${WORK}/out.h5)
  message(FATAL_ERROR "a refused render wrote out.h5")
endif()

# Item 4: the run's memory is estimated before anything is allocated (these
# ended in "internal error: std::bad_alloc").
refused(image_memory "the limit of" render small.toml -o out.h5 -q --backend cpu --width 65536 --height 65536)
refused(tau_bins_memory "--tau-bins: " tabulate --tau-bins 2000000000 --photons 2 --backend cpu -q -o bad.h5)
run(tabulate --tau-bins 2000000000 --photons 2 --backend cpu -q -o bad.h5)
string(FIND "${err}" "the limit of" at)
if(at EQUAL -1)
  message(FATAL_ERROR "tau_bins_memory: no figure and limit: ${err}")
endif()
