// Writing and running the gnuplot scripts of the evaluation and the tools.
#pragma once

#include <string>

namespace hglasm {

/// `text` as a gnuplot single-quoted string (a quote inside is doubled).
std::string gnuplotQuote(const std::string& text);

/// `text` as one POSIX shell word in single quotes.
std::string shellQuote(const std::string& text);

/// Runs `gnuplot SCRIPT`; true if it exited with 0.
bool runGnuplot(const std::string& script);

}  // namespace hglasm
