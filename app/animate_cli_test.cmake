# `nebula animate` end to end (ctest cli.animate, run with -DNEBULA=<binary>
# -DWORK=<scratch folder> -DFFMPEG_EXPECTED=ON|OFF): bad input is one line
# naming the key or option with nothing written; frames, resume, the frame at
# a keyframe equal to `nebula render` of that camera, and the MP4.
file(REMOVE_RECURSE ${WORK})
file(MAKE_DIRECTORY ${WORK})
set(ENV{NEBULA_CACHE_DIR} ${WORK}/cache)

string(CONCAT scene_head "[density]\nprocedural = { n = 12, size_pc = 2.0 }\n[[stars]]\nluminosity_lsun = 2e5\nclass = \"O5V\"\n"
               "[camera]\nposition = [1.0, -2.5, 1.0]\nlook_at = [1.0, 1.0, 1.0]\nwidth = 12\nheight = 10\nexposure = 0.02\n"
               "[render]\ndiffuse_photons = 4096\n")
set(key0 "[[animation.keyframes]]\ntime = 0.0\nposition = [1.0, -2.5, 1.0]\n")
set(key1 "[[animation.keyframes]]\ntime = 1.0\nposition = [3.0, -1.5, 1.2]\nfov_deg = 30\n")
file(WRITE ${WORK}/path.toml "${scene_head}${key0}${key1}")
file(WRITE ${WORK}/one_key.toml "${scene_head}${key0}")
file(WRITE ${WORK}/bad_key.toml "${scene_head}${key0}[[animation.keyframes]]\ntime = 1.0\nposition = \"far away\"\n")
file(WRITE ${WORK}/no_path.toml "${scene_head}")

# expect_refusal(NAME NEEDLE ARGS...): non-zero exit, one line naming NEEDLE, no frames folder.
function(expect_refusal name needle)
  execute_process(COMMAND ${NEBULA} animate ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err
                  WORKING_DIRECTORY ${WORK})
  if(rc EQUAL 0)
    message(FATAL_ERROR "${name}: expected failure, got exit 0: ${out}")
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
  if(EXISTS ${WORK}/bad)
    message(FATAL_ERROR "${name}: wrote ${WORK}/bad")
  endif()
endfunction()

set(q -q --backend cpu --table-photons 1000)
expect_refusal(one_key "animation.keyframes: has 1 keyframe" one_key.toml -o bad/f_%03d.h5 ${q})
expect_refusal(bad_key "animation.keyframes.1.position" bad_key.toml -o bad/f_%03d.h5 ${q})
expect_refusal(no_path "animation: the scene has no camera path" no_path.toml -o bad/f_%03d.h5 ${q})
expect_refusal(no_number "-o: 'bad/frame.h5' has no frame number" path.toml -o bad/frame.h5 ${q})
expect_refusal(two_numbers "-o:" path.toml -o bad/f_%d_%d.h5 ${q})
expect_refusal(no_output "-o PATTERN" path.toml ${q})
expect_refusal(extension "-o:" path.toml -o bad/f_%03d.jpg ${q})
expect_refusal(fps "--fps" path.toml -o bad/f_%03d.h5 --fps 0 ${q})
expect_refusal(to "--to" path.toml -o bad/f_%03d.h5 --to 5 ${q})
expect_refusal(duration "--duration" path.toml -o bad/f_%03d.h5 --duration -1 ${q})
expect_refusal(video_h5 "--video: needs PNG frames" path.toml -o bad/f_%03d.h5 --video bad.mp4 ${q})
if(PNG_EXPECTED)  # PNG frames need OpenImageIO; without it the PNG pattern is refused first
  expect_refusal(video_ext "--video" path.toml -o bad/f_%03d.png --video bad/movie.avi ${q})
else()
  expect_refusal(png_without_oiio "needs OpenImageIO" path.toml -o bad/f_%03d.png ${q})
endif()

# Frames: at 4 fps over 1 s, frames 0..4; frame 4 is the second keyframe.
execute_process(COMMAND ${NEBULA} animate path.toml -o frames/f_%03d.h5 --fps 4 ${q}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "animate failed (${rc}): ${out} ${err}")
endif()
file(GLOB frames ${WORK}/frames/f_*.h5)
list(LENGTH frames n)
if(NOT n EQUAL 5)
  message(FATAL_ERROR "expected 5 frames, found ${n}: ${frames}")
endif()
string(FIND "${out}" "one bake for all frames" at)
if(at EQUAL -1)
  message(FATAL_ERROR "animate did not report its one bake: ${out}")
endif()

# An existing frames folder: refused without --force or --resume, naming both; nothing changed.
file(TIMESTAMP ${WORK}/frames/f_000.h5 before "%s")
execute_process(COMMAND ${NEBULA} animate path.toml -o frames/f_%03d.h5 --fps 4 ${q}
                RESULT_VARIABLE rc ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
string(FIND "${err}" "--resume" at)
string(FIND "${err}" "error: -o:" at_o)
if(rc EQUAL 0 OR at EQUAL -1 OR at_o EQUAL -1)
  message(FATAL_ERROR "existing frames were not refused naming -o and --resume (${rc}): ${err}")
endif()

# Resume: only the missing frames are rendered.
file(REMOVE ${WORK}/frames/f_002.h5)
execute_process(COMMAND ${NEBULA} animate path.toml -o frames/f_%03d.h5 --fps 4 --resume ${q}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
string(FIND "${out}" "1 rendered, 4 kept" at)
if(NOT rc EQUAL 0 OR at EQUAL -1 OR NOT EXISTS ${WORK}/frames/f_002.h5)
  message(FATAL_ERROR "resume did not render just the missing frame (${rc}): ${out} ${err}")
endif()
# A resume with another frame rate is another run: refused.
execute_process(COMMAND ${NEBULA} animate path.toml -o frames/f_%03d.h5 --fps 8 --resume ${q}
                RESULT_VARIABLE rc ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
string(FIND "${err}" "error: --resume:" at)
if(rc EQUAL 0 OR at EQUAL -1)
  message(FATAL_ERROR "a resume of another run was not refused naming --resume (${rc}): ${err}")
endif()

# The frame at the second keyframe against `nebula render` of that camera: identical pixels.
execute_process(COMMAND ${NEBULA} render path.toml -o key1.h5 --set camera.position=[3.0,-1.5,1.2]
                        --set camera.fov_deg=30 ${q}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "render of the keyframe failed (${rc}): ${out} ${err}")
endif()
# (Every pixel above 1e-9 of the peak; animation_tests checks every pixel's bits.)
execute_process(COMMAND ${NEBULA} compare frames/f_004.h5 key1.h5 --json --signal 1e-9
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
string(REGEX MATCHALL "\"(rel_l1|worst_1pct)\": *[-+0-9.eE]+" errors "${out}")
list(LENGTH errors count)
if(NOT rc EQUAL 0 OR NOT count EQUAL 6)
  message(FATAL_ERROR "compare failed (${rc}): ${out} ${err}")
endif()
foreach(e IN LISTS errors)
  if(NOT e MATCHES ": *0$")
    message(FATAL_ERROR "the keyframe's frame differs from nebula render: ${out}")
  endif()
endforeach()

# The MP4.
if(FFMPEG_EXPECTED AND PNG_EXPECTED)
  execute_process(COMMAND ${NEBULA} animate path.toml -o png/f_%03d.png --fps 4 --video movie.mp4 ${q}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err WORKING_DIRECTORY ${WORK})
  if(NOT rc EQUAL 0 OR NOT EXISTS ${WORK}/movie.mp4)
    message(FATAL_ERROR "animate --video failed (${rc}): ${out} ${err}")
  endif()
  file(READ ${WORK}/movie.mp4 head LIMIT 12 HEX)
  if(NOT head MATCHES "^........66747970")
    message(FATAL_ERROR "movie.mp4 is not an ISO media file: ${head}")
  endif()
endif()
