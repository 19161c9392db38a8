#pragma once
// Frames to a video file through the `ffmpeg` program (Debian's ffmpeg) over a pipe: raw
// RGBA frames in, H.264 (libx264, yuv420p, CRF 18) in an MP4, MOV or MKV container out.
// The binary rather than libavcodec: no new build or link dependency (the encoder is found
// at run time, so a machine without it still builds and runs everything else), the API's
// version churn stays ffmpeg's problem, and ffprobe, which the tests use, comes with it.
//
// The video is written to PATH.tmp (beside a symlink's target) (the container named with -f) and renamed onto PATH by
// finish(): PATH never holds a partial video. ffmpeg runs in its own process group, so a
// Ctrl-C in the terminal reaches only softtled, which then finishes the frames it has.
#include <string>
#include <sys/types.h>

#include "render/image.h"

namespace softtled {

// The ffmpeg executable on PATH, "" when there is none.
std::string find_ffmpeg();

// Before any work: InputError unless PATH ends in .mp4, .mov or .mkv and can be written
// (check_output_file, naming `what`); ResourceError when ffmpeg is not on PATH.
void check_video_output(const std::string& path, const std::string& what);

class VideoEncoder {
 public:
  // Starts ffmpeg for w x h frames at fps; throws like check_video_output, or
  // ResourceError when ffmpeg cannot be started.
  VideoEncoder(std::string path, int w, int h, double fps);
  ~VideoEncoder();  // without finish(): ffmpeg is stopped and PATH.tmp removed
  VideoEncoder(const VideoEncoder&) = delete;
  VideoEncoder& operator=(const VideoEncoder&) = delete;

  // One frame, w x h RGBA, top row first. ResourceError (with ffmpeg's own message) when
  // ffmpeg has failed; the temporary is removed then.
  void write(const Image& frame);
  // Closes the input, waits for ffmpeg and renames PATH.tmp onto PATH; ResourceError (with
  // ffmpeg's message) when encoding failed, and then nothing is left at PATH or PATH.tmp.
  // Failed also when ffmpeg exits 0 but logged an error (it does so after "Error writing
  // trailer ...: File too large" on a full disk) or left no or an empty file.
  void finish();

  long frames() const { return frames_; }
  const std::string& path() const { return path_; }
  int width() const { return w_; }
  int height() const { return h_; }

 private:
  [[noreturn]] void fail(const std::string& what);
  void abort_child();
  void reaped();  // ffmpeg waited for: pid_ = -1, its group no longer tracked
  std::string ffmpeg_log() const;  // the last lines ffmpeg wrote to its standard error
  bool ffmpeg_logged_errors() const;  // ffmpeg (at -loglevel error) wrote any message
  std::string path_, target_, tmp_, log_;  // target_: path_, or the file a symlink there names
  int w_ = 0, h_ = 0;
  double fps_ = 0;
  int fd_ = -1;      // ffmpeg's standard input
  pid_t pid_ = -1;
  long frames_ = 0;
  int group_slot_ = -1, tmp_slot_ = -1, log_slot_ = -1;  // abrupt_exit.h's table
};

}  // namespace softtled
