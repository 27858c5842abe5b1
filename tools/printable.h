#pragma once
// Text from outside (file names, fields of a file, arguments) placed in a message for the
// terminal: control characters and bytes that are not UTF-8 are shown as \xNN (C1 controls as
// \uNNNN), so that a file named "\x1b[31m..." cannot drive the terminal. Valid UTF-8 text,
// tabs aside, is kept as it is.
#include <string>
#include <string_view>

namespace epichead::tools {

std::string printable(std::string_view text);

}  // namespace epichead::tools
