#include "core/atomic_write.hpp"

#include <filesystem>
#include <fstream>
#include <system_error>

#include "core/error.hpp"

namespace roiflow {

namespace fs = std::filesystem;

std::string partial_path(const std::string& path) {
  fs::path partial = path;
  const fs::path name = partial.filename();
  std::string hidden = ".";
  hidden += name.stem().string();
  hidden += ".partial";
  hidden += name.extension().string();
  partial.replace_filename(hidden);
  return partial.string();
}

void write_atomically(const std::string& path, const std::string& what,
                      const std::function<bool(const std::string& partial_path)>& write) {
  const std::string partial = partial_path(path);
  std::error_code ec;
  bool written = false;
  try {
    written = write(partial);
  } catch (const cv::Exception&) {
    written = false;
  } catch (...) {
    fs::remove(partial, ec);
    throw;
  }
  if (written) fs::rename(partial, path, ec);
  if (!written || ec) {
    fs::remove(partial, ec);
    throw Error("cannot write " + what + "'" + path + "'");
  }
}

void write_text_atomically(const std::string& path, const std::string& text) {
  write_atomically(path, "", [&](const std::string& partial) {
    std::ofstream out(partial, std::ios::binary);
    out << text;
    out.close();
    return static_cast<bool>(out);
  });
}

void write_bytes_atomically(const std::string& path, const std::string& what, const void* data,
                            std::size_t size) {
  write_atomically(path, what, [&](const std::string& partial) {
    std::ofstream out(partial, std::ios::binary);
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
    out.close();
    return static_cast<bool>(out);
  });
}

}  // namespace roiflow
