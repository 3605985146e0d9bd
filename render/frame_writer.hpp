// render/frame_writer.hpp — writes PNG frames on background threads so that encoding
// overlaps rendering; plus the output-folder check and the frame file naming.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace magsim::render {

/// `DIR/frame_000042.png` for index 42 (six digits, ffmpeg's `frame_%06d.png`).
std::string frame_path(const std::string& dir, int index);

/// Creates `dir` (and its parents) if missing and checks that a file can be created in it
/// (by creating and removing a probe file). Returns false with a message when `dir` is a
/// regular file, cannot be created, or is not writable.
bool check_output_dir(const std::string& dir, std::string* error);

/// A bounded queue of images written as PNG by `threads` worker threads. push() blocks
/// while `capacity` images are waiting, so memory stays bounded when writing is slower
/// than rendering. The first write error is kept: later pushes throw it, and so does
/// finish().
class FrameWriter {
 public:
  explicit FrameWriter(std::size_t capacity = 4, int threads = 1);
  ~FrameWriter();  ///< waits for the queue to drain; never throws
  FrameWriter(const FrameWriter&) = delete;
  FrameWriter& operator=(const FrameWriter&) = delete;

  /// Queues an RGB8 image (top row first) for writing to `path`. Throws
  /// std::runtime_error if an earlier write failed or finish() was called.
  void push(std::string path, int w, int h, std::vector<std::uint8_t> rgb);
  /// Writes everything queued, joins the threads, and throws std::runtime_error with the
  /// first error if any write failed. Further calls do nothing (but rethrow the error).
  void finish();
  /// Frames written successfully so far.
  std::size_t written() const;

 private:
  struct Job {
    std::string path;
    int w = 0, h = 0;
    std::vector<std::uint8_t> rgb;
  };
  void run();
  void join_all();

  std::size_t capacity_;
  std::vector<std::thread> threads_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::deque<Job> queue_;
  bool closing_ = false;
  std::string error_;
  std::size_t written_ = 0;
};

}  // namespace magsim::render
