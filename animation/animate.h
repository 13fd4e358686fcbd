#pragma once
// `nebula animate` as a library: a scene's camera path ([animation] keyframes,
// scene/camera_path.h) rendered to numbered frames with one bake (bands,
// tables, star bakes and the diffuse field are view-independent: prepare_grid
// once, render_prepared per frame), each frame written aside and renamed, an
// interrupted run resumed without redoing finished frames, and an MP4 made
// with ffmpeg. Every check runs before anything is written.
#include <optional>
#include <string>

#include "animation/frame_sequence.h"
#include "pipeline/render_scene.h"

namespace nebula {

struct AnimateOptions {
  std::string pattern;                     // "pattern": frames/frame_%04d.png (.png .exr .fits .h5)
  double fps = 30;                         // "fps"
  std::optional<double> duration;          // "duration": retime the path to last this long (s)
  std::optional<double> from, to;          // "from", "to": the part of the path to render (s)
  bool force = false;                      // render every frame again over existing ones
  bool resume = false;                     // keep the frames an interrupted run of the same path finished
  std::string existing_hint;               // appended to the refusal of existing frames (the front end's way out)
  std::string video;                       // "video": an .mp4 made from PNG frames, or ""
  RenderOptions render;                    // backend, table photons, smooth step; progress: bars for the bake
  bool progress = false;                   // a bar over the frames, with the time left
  bool quiet = false;                      // ffmpeg prints errors only
};

struct AnimateResult {
  FramePlan plan;
  long long rendered = 0, skipped = 0;    // skipped: finished by an earlier run (resume)
  double prepare_seconds = 0;              // bands, tables, bakes: once
  double render_seconds = 0, write_seconds = 0;  // over all rendered frames
  RunReport report;                        // of the bake and the first rendered frame
  std::string video;                       // written, or ""
  std::string manifest;                    // the run's record beside the frames
};

// Throws Error naming the scene key (animation, animation.keyframes...) or a
// ParameterError naming an AnimateOptions field, before writing anything.
AnimateResult animate(const Scene& scene, const AnimateOptions& options);

// The record of a run beside its frames (FOLDER/PREFIX.animate.txt): what a
// resumed run must match.
std::string manifest_path(const FramePattern& pattern);

}  // namespace nebula
