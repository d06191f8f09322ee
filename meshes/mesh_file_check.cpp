#include "meshes/mesh_file_check.h"

#include "core/errors.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

namespace dipper::meshes {

namespace {

/// Space, tab and line ends: the separators every reader agrees on (a form feed between two numbers was
/// one separator here and none for assimp, which then aborted).
bool separator(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

/// Words between separators, with the line each starts on.
class Words {
public:
    Words(const std::string& text, std::size_t start, std::size_t line) : text_(text), pos_(start), line_(line) {}

    /// The next word, or false at the end of the text.
    bool next(std::string& word)
    {
        while (pos_ < text_.size() && separator(text_[pos_])) {
            if (text_[pos_] == '\n') ++line_;
            ++pos_;
        }
        if (pos_ >= text_.size()) return false;
        const std::size_t begin = pos_;
        while (pos_ < text_.size() && !separator(text_[pos_])) ++pos_;
        word.assign(text_, begin, pos_ - begin);
        return true;
    }
    std::size_t line() const { return line_; }

private:
    const std::string& text_;
    std::size_t pos_, line_;
};

bool finite_number(const std::string& word, double& value)
{
    if (word.empty()) return false;
    char* end = nullptr;
    value = std::strtod(word.c_str(), &end);
    return end == word.c_str() + word.size() && std::isfinite(value);
}

bool whole_number(const std::string& word, long long& value)
{
    if (word.empty()) return false;
    char* end = nullptr;
    errno = 0;
    value = std::strtoll(word.c_str(), &end, 10);
    return end == word.c_str() + word.size() && errno == 0;
}

[[noreturn]] void refuse(const std::string& path, const std::string& format, const std::string& where, const std::string& what)
{
    throw InputError(concat("mesh file '", path, "' (", format, ") ", where, ": ", what));
}

std::string at_line(std::size_t line) { return concat("line ", line); }

void require_triangle_count(const std::string& path, const std::string& format, std::uint64_t count)
{
    if (count > kMaxMeshTriangles)
        refuse(path, format, "header", concat("claims ", count, " faces; at most ", kMaxMeshTriangles, " are read"));
}

// ---- STL ----------------------------------------------------------------------------------------

MeshFileSummary check_binary_stl(const std::string& path, const std::string& bytes)
{
    MeshFileSummary s{"binary STL", 0, 0};
    std::uint32_t n = 0;
    for (int k = 3; k >= 0; --k) n = (n << 8) | static_cast<unsigned char>(bytes[80 + static_cast<std::size_t>(k)]);
    s.faces = n;
    require_triangle_count(path, s.format, n);
    for (std::uint64_t t = 0; t < n; ++t)
        for (int c = 0; c < 12; ++c) {
            float value;
            std::memcpy(&value, bytes.data() + 84 + 50 * t + 4 * static_cast<std::uint64_t>(c), 4);
            if (!std::isfinite(value)) refuse(path, s.format, concat("triangle ", t), "a coordinate or normal is not finite");
        }
    s.vertices = 3 * s.faces;
    return s;
}

MeshFileSummary check_ascii_stl(const std::string& path, const std::string& text)
{
    MeshFileSummary s{"ASCII STL", 0, 0};
    Words words(text, 0, 1);
    std::string w;
    const auto cut_short = [&]() {
        refuse(path, s.format, at_line(words.line()), concat("the file ends after ", s.faces, " complete facets without 'endsolid': it is cut short"));
    };
    const auto expect = [&](const char* keyword) {
        if (!words.next(w)) cut_short();
        if (w != keyword) refuse(path, s.format, at_line(words.line()), concat("expected '", keyword, "' in facet ", s.faces + 1, "; got '", w, "'"));
    };
    const auto numbers = [&]() {
        for (int k = 0; k < 3; ++k) {
            double v;
            if (!words.next(w)) cut_short();
            if (!finite_number(w, v))
                refuse(path, s.format, at_line(words.line()), concat("expected a finite number in facet ", s.faces + 1, "; got '", w, "'"));
        }
    };
    // the words after a keyword on its own line (a solid's name)
    const auto skip_rest_of_line = [&]() {
        const std::size_t line = words.line();
        for (;;) {
            Words ahead = words;
            std::string peek;
            if (!ahead.next(peek) || ahead.line() != line) return;
            words.next(w);
        }
    };
    std::size_t solids = 0;
    while (words.next(w)) {
        if (w != "solid") refuse(path, s.format, at_line(words.line()), concat("expected 'solid'; got '", w, "'"));
        skip_rest_of_line();
        for (;;) {
            if (!words.next(w)) cut_short();
            if (w == "endsolid") break;
            if (w != "facet") refuse(path, s.format, at_line(words.line()), concat("expected 'facet' or 'endsolid'; got '", w, "'"));
            expect("normal");
            numbers();
            expect("outer");
            expect("loop");
            for (int k = 0; k < 3; ++k) {
                expect("vertex");
                numbers();
            }
            expect("endloop");
            expect("endfacet");
            ++s.faces;
            require_triangle_count(path, s.format, s.faces);
        }
        skip_rest_of_line();
        ++solids;
    }
    if (solids == 0) refuse(path, s.format, "line 1", "expected 'solid'");
    s.vertices = 3 * s.faces;
    return s;
}

// ---- PLY ----------------------------------------------------------------------------------------

struct PlyProperty {
    std::string name;
    int size = 0;        ///< bytes of a scalar, or of a list's items
    int count_size = 0;  ///< bytes of a list's count; 0 for a scalar
    bool is_float = false;
};

struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> properties;
};

int ply_type_size(const std::string& type, bool& is_float)
{
    is_float = type == "float" || type == "float32" || type == "double" || type == "float64";
    if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
    if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
    if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" || type == "float32") return 4;
    if (type == "double" || type == "float64") return 8;
    return 0;
}

/// A binary scalar as a double (the file's byte order).
double ply_scalar(const unsigned char* p, int size, bool is_float, bool little)
{
    unsigned char b[8];
    for (int k = 0; k < size; ++k) b[k] = little ? p[k] : p[size - 1 - k];
    if (is_float) {
        if (size == 4) {
            float f;
            std::memcpy(&f, b, 4);
            return f;
        }
        double d;
        std::memcpy(&d, b, 8);
        return d;
    }
    std::uint64_t v = 0;
    for (int k = size - 1; k >= 0; --k) v = (v << 8) | b[k];
    return static_cast<double>(v);  // counts and indices: negative ones read as huge and are refused
}

MeshFileSummary check_ply(const std::string& path, const std::string& bytes)
{
    MeshFileSummary s{"PLY", 0, 0};
    // the header: lines up to end_header
    std::size_t pos = 0, line = 0;
    std::string format;
    std::vector<PlyElement> elements;
    bool ended = false;
    while (pos < bytes.size() && !ended) {
        const std::size_t eol = bytes.find_first_of("\r\n", pos);  // CR, LF or CR LF end a line
        if (eol == std::string::npos) refuse(path, s.format, at_line(line + 1), "the header ends without 'end_header'");
        std::string text = bytes.substr(pos, eol - pos);
        pos = eol + (bytes.compare(eol, 2, "\r\n") == 0 ? 2 : 1);
        ++line;
        std::vector<std::string> w;
        Words words(text, 0, line);
        for (std::string x; words.next(x);) w.push_back(x);
        if (line == 1) {
            if (w.size() != 1 || w[0] != "ply") refuse(path, s.format, at_line(line), "expected 'ply'");
            continue;
        }
        if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
        if (w[0] == "format") {
            if (w.size() != 3 || w[2] != "1.0" || (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian"))
                refuse(path, s.format, at_line(line), concat("expected 'format ascii 1.0' or a binary_little_endian or binary_big_endian 1.0; got '", text, "'"));
            format = w[1];
        } else if (w[0] == "element") {
            long long count = -1;
            if (w.size() != 3 || !whole_number(w[2], count) || count < 0)
                refuse(path, s.format, at_line(line), concat("expected 'element NAME COUNT' with a whole count; got '", text, "'"));
            elements.push_back({w[1], static_cast<std::uint64_t>(count), {}});
        } else if (w[0] == "property") {
            if (elements.empty()) refuse(path, s.format, at_line(line), "a property before any element");
            PlyProperty p;
            if (w.size() == 5 && w[1] == "list") {
                bool count_float = false;
                p.count_size = ply_type_size(w[2], count_float);
                p.size = ply_type_size(w[3], p.is_float);
                if (p.count_size == 0 || count_float || p.size == 0 || p.is_float)
                    refuse(path, s.format, at_line(line), concat("expected 'property list COUNT_TYPE INDEX_TYPE NAME' of integer types; got '", text, "'"));
                p.name = w[4];
            } else if (w.size() == 3) {
                p.size = ply_type_size(w[1], p.is_float);
                if (p.size == 0) refuse(path, s.format, at_line(line), concat("unknown property type '", w[1], "'"));
                p.name = w[2];
            } else {
                refuse(path, s.format, at_line(line), concat("expected 'property TYPE NAME' or 'property list ...'; got '", text, "'"));
            }
            elements.back().properties.push_back(p);
        } else if (w[0] == "end_header") {
            ended = true;
        } else {
            refuse(path, s.format, at_line(line), concat("unknown header line '", text, "'"));
        }
    }
    if (!ended) refuse(path, s.format, at_line(line), "the header ends without 'end_header'");
    if (format.empty()) refuse(path, s.format, "header", "no 'format' line");
    s.format = format == "ascii" ? "ASCII PLY" : "binary PLY";

    // the vertices with x, y, z and the faces with their index list, and nothing the reader cannot place
    const PlyElement* vertex = nullptr;
    const PlyElement* face = nullptr;
    for (const PlyElement& e : elements) {
        if (e.name == "vertex") vertex = &e;
        if (e.name == "face") face = &e;
    }
    if (!vertex) refuse(path, s.format, "header", "no 'element vertex'");
    if (!face) refuse(path, s.format, "header", "no 'element face'");
    for (const char* axis : {"x", "y", "z"})
        if (std::none_of(vertex->properties.begin(), vertex->properties.end(),
                         [&](const PlyProperty& p) { return p.name == axis && p.count_size == 0; }))
            refuse(path, s.format, "header", concat("the vertex element has no scalar property '", axis, "'"));
    int face_list = -1;
    for (std::size_t k = 0; k < face->properties.size(); ++k)
        if (face->properties[k].count_size > 0 && (face->properties[k].name == "vertex_indices" || face->properties[k].name == "vertex_index"))
            face_list = static_cast<int>(k);
    if (face_list < 0) refuse(path, s.format, "header", "the face element has no list property 'vertex_indices'");
    require_triangle_count(path, s.format, face->count);
    if (vertex->count > 3 * kMaxMeshTriangles)
        refuse(path, s.format, "header", concat("claims ", vertex->count, " vertices; at most ", 3 * kMaxMeshTriangles, " are read"));
    s.vertices = vertex->count;
    s.faces = face->count;

    // the body: each item of each element in order; every count met, every index inside the vertices
    const std::size_t body = bytes.size() - pos;
    std::uint64_t least = 0;  // the fewest bytes the claimed counts take (a header of 10^11 vertices is refused here)
    for (const PlyElement& e : elements) {
        std::uint64_t item = 0;
        for (const PlyProperty& p : e.properties) item += format == "ascii" ? 2 : static_cast<std::uint64_t>(p.count_size > 0 ? p.count_size : p.size);
        if (e.count > 0 && item == 0) refuse(path, s.format, "header", concat("element '", e.name, "' has ", e.count, " items and no property"));
        if (item > 0 && e.count > (std::uint64_t{1} << 40) / item) least = std::uint64_t{1} << 40;
        else least += e.count * item;
    }
    if (least > body)
        refuse(path, s.format, "body", concat("its header claims items that take at least ", least, " bytes; the file holds ", body,
                                               " after the header: it is cut short or its counts are wrong"));
    const auto check_face = [&](std::uint64_t f, double n, const std::vector<double>& indices, const std::string& where) {
        if (n < 3) refuse(path, s.format, where, concat("face ", f, " has ", n, " vertices; a face needs at least 3"));
        for (double i : indices)
            if (!(i >= 0.0 && i < static_cast<double>(vertex->count)))
                refuse(path, s.format, where, concat("face ", f, " names vertex ", i, "; the file has ", vertex->count));
    };
    if (format == "ascii") {
        // one item a line, as readers take them: a line with more or fewer words than its item needs is
        // refused (a vertex line of four words made the next line a face of none, and assimp aborted)
        std::size_t at = pos, row = line;
        for (const PlyElement& e : elements)
            for (std::uint64_t k = 0; k < e.count; ++k) {
                std::string text;
                do {
                    if (at >= bytes.size())
                        refuse(path, s.format, at_line(row + 1), concat("the file ends in ", e.name, " ", k, " of ", e.count, ": it is cut short"));
                    std::size_t eol = bytes.find_first_of("\r\n", at);  // a lone CR ends a line too, for readers
                    if (eol == std::string::npos) eol = bytes.size();
                    text = bytes.substr(at, eol - at);
                    at = eol + 1;
                    ++row;
                } while (text.find_first_not_of(" \t\r") == std::string::npos);
                std::vector<std::string> w;
                Words words(text, 0, row);
                for (std::string x; words.next(x);) w.push_back(x);
                std::size_t next = 0;
                for (std::size_t q = 0; q < e.properties.size(); ++q) {
                    const PlyProperty& p = e.properties[q];
                    const auto number = [&](const char* what) {
                        double v;
                        if (next >= w.size())
                            refuse(path, s.format, at_line(row), concat(e.name, " ", k, " has ", w.size(), " numbers on its line; its properties need more"));
                        if (!finite_number(w[next], v))
                            refuse(path, s.format, at_line(row), concat("expected ", what, " in ", e.name, " ", k, "; got '", w[next], "'"));
                        ++next;
                        return v;
                    };
                    if (p.count_size == 0) {
                        number("a finite number");
                        continue;
                    }
                    const double n = number("a list's count");
                    if (!(n >= 0.0 && n <= 1000.0 && n == std::floor(n)))
                        refuse(path, s.format, at_line(row), concat("a list of ", n, " items in ", e.name, " ", k));
                    std::vector<double> items(static_cast<std::size_t>(n));
                    for (double& x : items) x = number("an index");
                    if (&e == face && static_cast<int>(q) == face_list) check_face(k, n, items, at_line(row));
                }
                if (next != w.size())
                    refuse(path, s.format, at_line(row), concat(e.name, " ", k, " has ", w.size(), " numbers on its line; its properties take ", next));
            }
        return s;
    }
    const bool little = format == "binary_little_endian";
    const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
    std::size_t at = pos;
    for (const PlyElement& e : elements)
        for (std::uint64_t k = 0; k < e.count; ++k)
            for (std::size_t q = 0; q < e.properties.size(); ++q) {
                const PlyProperty& p = e.properties[q];
                const auto need = [&](std::size_t n) {
                    if (at + n > bytes.size())
                        refuse(path, s.format, concat("byte ", at), concat("the file ends in ", e.name, " ", k, " of ", e.count, ": it is cut short"));
                };
                if (p.count_size == 0) {
                    need(static_cast<std::size_t>(p.size));
                    if (p.is_float && !std::isfinite(ply_scalar(data + at, p.size, true, little)))
                        refuse(path, s.format, concat("byte ", at), concat("a number that is not finite in ", e.name, " ", k));
                    at += static_cast<std::size_t>(p.size);
                    continue;
                }
                need(static_cast<std::size_t>(p.count_size));
                const double n = ply_scalar(data + at, p.count_size, false, little);
                at += static_cast<std::size_t>(p.count_size);
                if (n > 1000.0) refuse(path, s.format, concat("byte ", at), concat("a list of ", n, " items in ", e.name, " ", k));
                const auto items_n = static_cast<std::size_t>(n);
                need(items_n * static_cast<std::size_t>(p.size));
                std::vector<double> items(items_n);
                for (std::size_t i = 0; i < items_n; ++i) items[i] = ply_scalar(data + at + i * static_cast<std::size_t>(p.size), p.size, false, little);
                if (&e == face && static_cast<int>(q) == face_list) check_face(k, n, items, concat("byte ", at));
                at += items_n * static_cast<std::size_t>(p.size);
            }
    return s;
}

// ---- OBJ ----------------------------------------------------------------------------------------

MeshFileSummary check_obj(const std::string& path, const std::string& text)
{
    MeshFileSummary s{"OBJ", 0, 0};
    std::size_t pos = 0, line = 0;
    while (pos < text.size()) {
        std::size_t eol = text.find('\n', pos);
        if (eol == std::string::npos) eol = text.size();
        const std::string row = text.substr(pos, eol - pos);
        pos = eol + 1;
        ++line;
        Words words(row, 0, line);
        std::string key, w;
        if (!words.next(key)) continue;
        if (key == "v") {
            for (int k = 0; k < 3; ++k) {
                double v;
                if (!words.next(w) || !finite_number(w, v))
                    refuse(path, s.format, at_line(line), concat("a vertex needs three finite coordinates; got '", row, "'"));
            }
            ++s.vertices;
        } else if (key == "f") {
            int corners = 0;
            while (words.next(w)) {
                long long i = 0;
                if (!whole_number(w.substr(0, w.find('/')), i) || i == 0)
                    refuse(path, s.format, at_line(line), concat("a face corner must start with a vertex number; got '", w, "'"));
                const long long resolved = i > 0 ? i : static_cast<long long>(s.vertices) + 1 + i;
                if (resolved < 1 || resolved > static_cast<long long>(s.vertices))
                    refuse(path, s.format, at_line(line), concat("face corner ", i, " names a vertex that does not exist (", s.vertices, " so far)"));
                ++corners;
            }
            if (corners < 3) refuse(path, s.format, at_line(line), concat("a face needs at least three corners; got '", row, "'"));
            ++s.faces;
            require_triangle_count(path, s.format, s.faces);
        }
    }
    if (s.faces == 0) refuse(path, s.format, "file", "no face ('f' line)");
    return s;
}

std::string lower_extension(const std::string& path)
{
    std::string e = std::filesystem::path(path).extension().string();
    std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return e;
}

}  // namespace

MeshFileSummary check_mesh_file(const std::string& path)
{
    std::error_code error;
    const std::uintmax_t size = std::filesystem::file_size(path, error);
    if (error) throw InputError(concat("mesh file '", path, "' cannot be read: ", error.message()));
    if (size > kMaxMeshFileBytes)
        throw InputError(concat("mesh file '", path, "' is ", size, " bytes; at most ", kMaxMeshFileBytes, " are read"));
    std::ifstream in(path, std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (!in.eof() && in.fail()) throw InputError(concat("mesh file '", path, "' cannot be read"));
    const std::string ext = lower_extension(path);
    if (bytes.compare(0, 4, "ply\n") == 0 || bytes.compare(0, 5, "ply\r\n") == 0) return check_ply(path, bytes);
    if (ext == ".stl") {
        if (bytes.size() >= 84) {
            std::uint64_t n = 0;
            for (int k = 3; k >= 0; --k) n = (n << 8) | static_cast<unsigned char>(bytes[80 + static_cast<std::size_t>(k)]);
            if (bytes.size() == 84 + 50 * n) return check_binary_stl(path, bytes);
        }
        std::size_t first = 0;
        while (first < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[first]))) ++first;
        if (bytes.compare(first, 5, "solid") == 0) return check_ascii_stl(path, bytes);
        throw InputError(concat("mesh file '", path, "' is neither a binary STL (", bytes.size(),
                                " bytes where its triangle count asks for 84 + 50 per triangle) nor an ASCII STL (it does not start with 'solid')"));
    }
    if (ext == ".ply") throw InputError(concat("mesh file '", path, "' does not start with the line 'ply'"));
    if (ext == ".obj") return check_obj(path, bytes);
    throw InputError(concat("mesh file '", path, "' is not an STL, OBJ or PLY file (its extension is '", ext, "')"));
}


}  // namespace dipper::meshes
