// render/frame_writer.cpp — background PNG writing and the output folder helpers.
#include "render/frame_writer.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "render/png_io.hpp"

namespace magsim::render {

namespace fs = std::filesystem;

std::string frame_path(const std::string& dir, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d.png", index);
  return (fs::path(dir) / name).string();
}

bool check_output_dir(const std::string& dir, std::string* error) {
  auto fail = [&](const std::string& msg) {
    if (error) *error = msg;
    return false;
  };
  if (dir.empty()) return fail("output folder: empty path");
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (fs::exists(st)) {
    if (!fs::is_directory(st))
      return fail("output folder " + dir + " exists and is not a directory");
  } else {
    fs::create_directories(dir, ec);
    if (ec) return fail("cannot create output folder " + dir + ": " + ec.message());
  }
  // writability: create and remove a probe file (access() is wrong for root and ACLs)
  const fs::path probe = fs::path(dir) / (".magsim_probe_" + std::to_string(::getpid()));
  std::FILE* f = std::fopen(probe.c_str(), "wb");
  if (!f) return fail("output folder " + dir + " is not writable");
  std::fclose(f);
  fs::remove(probe, ec);
  return true;
}

FrameWriter::FrameWriter(std::size_t capacity, int threads)
    : capacity_(capacity == 0 ? 1 : capacity) {
  const int n = threads < 1 ? 1 : threads;
  for (int i = 0; i < n; ++i) threads_.emplace_back([this] { run(); });
}

FrameWriter::~FrameWriter() { join_all(); }

void FrameWriter::push(std::string path, int w, int h, std::vector<std::uint8_t> rgb) {
  std::unique_lock<std::mutex> lock(mutex_);
  not_full_.wait(lock, [&] { return queue_.size() < capacity_ || !error_.empty() || closing_; });
  if (!error_.empty()) throw std::runtime_error(error_);
  if (closing_) throw std::runtime_error("FrameWriter::push after finish()");
  queue_.push_back(Job{std::move(path), w, h, std::move(rgb)});
  not_empty_.notify_one();
}

void FrameWriter::finish() {
  join_all();
  std::lock_guard<std::mutex> lock(mutex_);
  if (!error_.empty()) throw std::runtime_error(error_);
}

std::size_t FrameWriter::written() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return written_;
}

void FrameWriter::join_all() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    closing_ = true;
  }
  not_empty_.notify_all();
  not_full_.notify_all();
  for (std::thread& t : threads_)
    if (t.joinable()) t.join();
}

void FrameWriter::run() {
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      not_empty_.wait(lock, [&] { return !queue_.empty() || closing_; });
      if (queue_.empty()) return;  // closing and drained
      job = std::move(queue_.front());
      queue_.pop_front();
    }
    not_full_.notify_one();
    std::string err;
    bool ok = false;
    if (job.rgb.size() != std::size_t(job.w) * std::size_t(job.h) * 3)
      err = "FrameWriter: image for " + job.path + " has the wrong size";
    else
      ok = write_png(job.path, job.w, job.h, job.rgb.data(), &err);
    std::lock_guard<std::mutex> lock(mutex_);
    if (ok) ++written_;
    else if (error_.empty()) error_ = err;
    if (!ok) not_full_.notify_all();  // wake a blocked push so it can throw
  }
}

}  // namespace magsim::render
