#include "scenario/detail/text_checks.h"

#include "core/errors.h"

#include <cstdio>

namespace dipper::scenario::detail {

/// The text must be UTF-8 (YAML's encoding; names go into JSON and folder names): the first byte that
/// breaks it is refused with its line and column.
void require_utf8(const std::string& text, const std::string& source)
{
    std::size_t line = 1, column = 1;
    for (std::size_t k = 0; k < text.size();) {
        const auto b = static_cast<unsigned char>(text[k]);
        std::size_t n = b < 0x80 ? 1 : (b >> 5) == 0x6 ? 2 : (b >> 4) == 0xE ? 3 : (b >> 3) == 0x1E ? 4 : 0;
        bool ok = n > 0 && k + n <= text.size() && !(n == 2 && b < 0xC2);
        for (std::size_t c = 1; ok && c < n; ++c) ok = (static_cast<unsigned char>(text[k + c]) & 0xC0) == 0x80;
        if (ok && n == 3) {
            const auto b1 = static_cast<unsigned char>(text[k + 1]);
            ok = !(b == 0xE0 && b1 < 0xA0) && !(b == 0xED && b1 >= 0xA0);  // overlong, surrogates
        }
        if (ok && n == 4) {
            const auto b1 = static_cast<unsigned char>(text[k + 1]);
            ok = !(b == 0xF0 && b1 < 0x90) && !(b == 0xF4 && b1 >= 0x90) && b <= 0xF4;
        }
        if (!ok) {
            char hex[8];
            std::snprintf(hex, sizeof hex, "0x%02X", b);
            throw InputError(concat(source, ":", line, ":", column, ": the byte ", hex,
                                    " is not UTF-8; a scenario file is UTF-8 text (save it as UTF-8)"));
        }
        if (b == '\n') ++line, column = 1;
        else ++column;
        k += n;
    }
}

/// A quoted scalar the file never closes: yaml-cpp reads it to the end of the file as one string, so that
/// every key after it went missing ("time: got nothing"). A quote opens a scalar only where one starts.
void require_quotes_closed(const std::string& text, const std::string& source)
{
    std::size_t line = 1, column = 0, open_line = 0, open_column = 0;
    char quote = 0;
    bool scalar_may_start = true, comment = false;
    for (std::size_t k = 0; k < text.size(); ++k) {
        const char c = text[k];
        ++column;
        if (c == '\n') {
            ++line;
            column = 0;
            comment = false;
            if (!quote) scalar_may_start = true;
            continue;
        }
        if (comment) continue;
        if (quote) {
            if (quote == '"' && c == '\\') ++k, ++column;  // an escape: the next character is part of the string
            else if (c == quote && quote == '\'' && k + 1 < text.size() && text[k + 1] == '\'') ++k, ++column;  // '' inside '...'
            else if (c == quote) quote = 0, scalar_may_start = false;
            continue;
        }
        if (c == ' ' || c == '\t') continue;
        if (c == '#' && (k == 0 || text[k - 1] == ' ' || text[k - 1] == '\t' || scalar_may_start)) {
            comment = true;
            continue;
        }
        if ((c == '"' || c == '\'') && scalar_may_start) {
            quote = c;
            open_line = line;
            open_column = column;
            continue;
        }
        // a new scalar may start after a mapping's ':' or a sequence's '-' followed by a space, and inside [ { ,
        const char next = k + 1 < text.size() ? text[k + 1] : '\n';
        scalar_may_start = c == '[' || c == '{' || c == ',' || ((c == ':' || c == '-' || c == '?') && (next == ' ' || next == '\n' || next == '\t'));
    }
    if (quote)
        throw InputError(concat(source, ":", open_line, ":", open_column, ": the quoted value that starts here (", quote,
                                ") is never closed; close it with ", quote, " on its line"));
}

/// One YAML document: a '---' or '...' line after content starts another, which YAML::Load ignored without a
/// word (YAML::LoadAll, which would count them, loops for ever on some inputs, such as a line "[0], # x").
void require_one_document(const std::string& text, const std::string& source)
{
    bool content = false;
    std::size_t line = 0, from = 0;
    while (from <= text.size()) {
        std::size_t eol = text.find('\n', from);
        if (eol == std::string::npos) eol = text.size();
        const std::string row = text.substr(from, eol - from);
        from = eol + 1;
        ++line;
        const bool marker = (row.rfind("---", 0) == 0 || row.rfind("...", 0) == 0) &&
                            (row.size() == 3 || row[3] == ' ' || row[3] == '\t' || row[3] == '\r');
        if (marker && content)
            throw InputError(concat(source, ":", line, ": '", row.substr(0, 3), "' ends the scenario's YAML document; a scenario file holds one"));
        const std::size_t first = row.find_first_not_of(" \t\r");
        if (!marker && first != std::string::npos && row[first] != '#') content = true;
    }
}

}  // namespace dipper::scenario::detail
