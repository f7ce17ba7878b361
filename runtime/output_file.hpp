// Writing a whole file and knowing that it arrived: a stream reports a full disk only when its buffer is
// flushed, and a small file is flushed by close(), so the checks come after both.
#pragma once

#include <string>

namespace fusecal {

// Creates or truncates `path` and writes `bytes`; throws std::runtime_error naming the file and the
// system's reason ("out.json: cannot write (No space left on device)") when any step fails.
void WriteFileChecked(const std::string& path, const std::string& bytes);

}  // namespace fusecal
