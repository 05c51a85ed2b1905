// Writes the seed corpus of every fuzz target: fuzz_seeds DIR -> DIR/<target>/seed_<n>.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "seed_corpus.hpp"

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_seeds DIR\n");
    return 2;
  }
  try {
    const fs::path root = argv[1];
    fs::create_directories(root);
    for (const auto& [target, seeds] : roiflow::fuzz::seed_corpus(root)) {
      fs::create_directories(root / target);
      for (std::size_t i = 0; i < seeds.size(); ++i) {
        std::ofstream out(root / target / ("seed_" + std::to_string(i)), std::ios::binary);
        out << seeds[i];
        if (!out) throw std::runtime_error("cannot write a seed under " + root.string());
      }
      std::printf("%s: %zu seeds\n", target.c_str(), seeds.size());
    }
    fs::remove(root / "seed.flo");
    fs::remove(root / "seed.csv");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz_seeds: %s\n", e.what());
    return 1;
  }
  return 0;
}
