#include "hglasm_odometry/evaluation/gnuplot.h"

#include <cstdlib>

namespace hglasm {

std::string gnuplotQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    quoted += c;
    if (c == '\'') quoted += '\'';
  }
  return quoted + "'";
}

std::string shellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

bool runGnuplot(const std::string& script) {
  return std::system(("gnuplot " + shellQuote(script)).c_str()) == 0;
}

}  // namespace hglasm
