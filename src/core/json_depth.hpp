// How deeply a JSON text nests its arrays and objects (brackets outside strings), so that a
// reader can refuse a document nested far deeper than any of its files (strokes, .series) before
// a parser or a walk recurses through it (100,000 levels overflowed the stack).
#pragma once

#include <algorithm>
#include <string>

namespace morphogen {

// The deepest nesting level reached in text (0: a bare value; [[1]]: 2).
inline int json_nesting_depth(const std::string& text) {
  int depth = 0, most = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped)
        escaped = false;
      else if (c == '\\')
        escaped = true;
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"')
      in_string = true;
    else if (c == '[' || c == '{')
      most = std::max(most, ++depth);
    else if (c == ']' || c == '}')
      --depth;
  }
  return most;
}

// Deeper than this, a strokes or .series file is refused (theirs nest 3-5 levels).
constexpr int kMaxJsonDepth = 64;

} // namespace morphogen
