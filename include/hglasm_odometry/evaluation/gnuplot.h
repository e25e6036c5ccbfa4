// Text for the gnuplot scripts the evaluation writes.
#pragma once

#include <string>

namespace hglasm {

/// `text` as a gnuplot single-quoted string (a quote inside is doubled).
inline std::string gnuplotQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    quoted += c;
    if (c == '\'') quoted += '\'';
  }
  return quoted + "'";
}

}  // namespace hglasm
