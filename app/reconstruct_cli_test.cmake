# `nebula reconstruct` end to end (run by ctest with -DNEBULA=<binary>
# -DWORK=<scratch folder>): an axial scene rendered at the thesis'
# inclination 0, reconstructed, the map rendered back through [axial] file;
# bad input gives one line naming the option and writes nothing.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})

function(run name)
  execute_process(COMMAND ${NEBULA} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  WORKING_DIRECTORY ${WORK})
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name}: exit ${rc}: ${err}")
  endif()
  message(STATUS "${name}: ${out}")
endfunction()

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

# The nebula seen perpendicular to its axis: 32 texels along x, 16 radially,
# one pixel per texel, the axis through the image's middle row boundary.
file(WRITE ${WORK}/nebula.toml
     "bands = [\"B\", \"V\", \"R\"]\n[axial]\nsynthetic = \"lopsided\"\nnx = 32\nnr = 16\nlength_pc = 32.0\n"
     "axis = [1.0, 0.0, 0.0]\ntau_scale = 0.0001\n"
     "[camera]\nkind = \"orthographic\"\nposition = [16.0, 0.0, -40.0]\nlook_at = [16.0, 0.0, 0.0]\n"
     "up = [0.0, 1.0, 0.0]\northo_width = 32.0\nwidth = 32\nheight = 32\n")
run(render render nebula.toml -o input.h5)
run(reconstruct reconstruct input.h5 --axis 0,16,0 -o map.h5)
if(NOT EXISTS ${WORK}/map.h5)
  message(FATAL_ERROR "reconstruct: no map.h5")
endif()
run(reconstruct_powell reconstruct input.h5 --axis 0,16,0 --method powell --backend cpu -o map_powell.h5)
# The map renders as an [axial] file.
file(WRITE ${WORK}/again.toml
     "bands = [\"B\", \"V\", \"R\"]\n[axial]\nfile = \"map.h5\"\nemission_prefix = \"emission_\"\nlength_pc = 32.0\n"
     "axis = [1.0, 0.0, 0.0]\n"
     "[camera]\nkind = \"orthographic\"\nposition = [16.0, 0.0, -40.0]\nlook_at = [16.0, 0.0, 0.0]\n"
     "up = [0.0, 1.0, 0.0]\northo_width = 32.0\nwidth = 32\nheight = 32\n")
run(render_again render again.toml -o again.h5)

expect_failure(exists "map.h5" reconstruct input.h5 --axis 0,16,0 -o map.h5)
expect_failure(axis_outside "--axis: the point (40, 16) lies outside" reconstruct input.h5 --axis 40,16,0 -o bad.h5)
expect_failure(axis_two_numbers "--axis" reconstruct input.h5 --axis 0,16 -o bad.h5)
expect_failure(unknown_method "--method: 'simplex' is not a method" reconstruct input.h5 --axis 0,16,0 --method simplex -o bad.h5)
expect_failure(radius "--radius" reconstruct input.h5 --axis 0,16,0 --radius 40 -o bad.h5)
expect_failure(smoothness "--smoothness" reconstruct input.h5 --axis 0,16,0 --smoothness -1 -o bad.h5)
expect_failure(not_h5 "-o" reconstruct input.h5 --axis 0,16,0 -o bad.png)
expect_failure(missing "missing.h5" reconstruct missing.h5 --axis 0,16,0 -o bad.h5)
expect_failure(nnls_on_cuda "--backend" reconstruct input.h5 --axis 0,16,0 --backend cuda -o bad.h5)

# A NaN pixel and an image of the wrong rank (h5py, a project dependency).
execute_process(COMMAND ${PYTHON} -c "
import shutil, h5py, numpy as np
shutil.copy('input.h5', 'nan.h5')
with h5py.File('nan.h5', 'r+') as f:
    d = f['image'][...]
    d[1, 3, 5] = np.nan
    f['image'][...] = d
with h5py.File('flat.h5', 'w') as f:
    f['image'] = np.ones((32, 32), dtype='f4')
" WORKING_DIRECTORY ${WORK} RESULT_VARIABLE py)
if(NOT py EQUAL 0)
  message(FATAL_ERROR "python3 with h5py is needed (scripts/install-deps.sh installs it)")
endif()
expect_failure(nan "nan.h5" reconstruct nan.h5 --axis 0,16,0 -o bad.h5)
expect_failure(rank "flat.h5" reconstruct flat.h5 --axis 0,16,0 -o bad.h5)
