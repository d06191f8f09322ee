// Checks of a scenario file's text before YAML reads it: what yaml-cpp accepts without a word or loops on.
#pragma once

#include <string>

namespace dipper::scenario::detail {

/// The text must be UTF-8 (YAML's encoding; names go into JSON and folder names): the first byte that
/// breaks it is refused with its line and column.
void require_utf8(const std::string& text, const std::string& source);
/// A quoted scalar the file never closes is refused where it opens (yaml-cpp read it to the end of the file).
void require_quotes_closed(const std::string& text, const std::string& source);
/// One YAML document: a '---' or '...' line after content is refused.
void require_one_document(const std::string& text, const std::string& source);

}  // namespace dipper::scenario::detail
