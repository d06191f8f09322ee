#include "wear/image.h"

#include "core/errors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <map>

namespace dipper::wear {

namespace {

// 5x7 glyphs, one string of 5 characters per row, '#' set
const std::map<char, std::array<const char*, 7>>& font()
{
    static const std::map<char, std::array<const char*, 7>> glyphs{
        {'0', {".###.", "#...#", "#..##", "#.#.#", "##..#", "#...#", ".###."}},
        {'1', {"..#..", ".##..", "..#..", "..#..", "..#..", "..#..", ".###."}},
        {'2', {".###.", "#...#", "....#", "...#.", "..#..", ".#...", "#####"}},
        {'3', {"#####", "...#.", "..#..", "...#.", "....#", "#...#", ".###."}},
        {'4', {"...#.", "..##.", ".#.#.", "#..#.", "#####", "...#.", "...#."}},
        {'5', {"#####", "#....", "####.", "....#", "....#", "#...#", ".###."}},
        {'6', {"..##.", ".#...", "#....", "####.", "#...#", "#...#", ".###."}},
        {'7', {"#####", "....#", "...#.", "..#..", ".#...", ".#...", ".#..."}},
        {'8', {".###.", "#...#", "#...#", ".###.", "#...#", "#...#", ".###."}},
        {'9', {".###.", "#...#", "#...#", ".####", "....#", "...#.", ".##.."}},
        {'.', {".....", ".....", ".....", ".....", ".....", ".##..", ".##.."}},
        {'-', {".....", ".....", ".....", "#####", ".....", ".....", "....."}},
        {'+', {".....", "..#..", "..#..", "#####", "..#..", "..#..", "....."}},
        {'e', {".....", ".....", ".###.", "#...#", "#####", "#....", ".###."}},
        {'m', {".....", ".....", "##.#.", "#.#.#", "#.#.#", "#...#", "#...#"}},
        {'/', {".....", "....#", "...#.", "..#..", ".#...", "#....", "....."}},
        {'t', {".#...", ".#...", "###..", ".#...", ".#...", ".#..#", "..##."}},
        {'w', {".....", ".....", "#...#", "#...#", "#.#.#", "#.#.#", ".#.#."}},
        {'a', {".....", ".....", ".###.", "....#", ".####", "#...#", ".####"}},
        {'r', {".....", ".....", "#.##.", "##..#", "#....", "#....", "#...."}},
        {'(', {"...#.", "..#..", ".#...", ".#...", ".#...", "..#..", "...#."}},
        {')', {".#...", "..#..", "...#.", "...#.", "...#.", "..#..", ".#..."}},
        {' ', {".....", ".....", ".....", ".....", ".....", ".....", "....."}},
    };
    return glyphs;
}

std::uint32_t crc32(const std::uint8_t* data, std::size_t n, std::uint32_t crc = 0)
{
    static const std::array<std::uint32_t, 256> table = [] {
        std::array<std::uint32_t, 256> t{};
        for (std::uint32_t i = 0; i < 256; ++i) {
            std::uint32_t c = i;
            for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
            t[i] = c;
        }
        return t;
    }();
    crc = ~crc;
    for (std::size_t i = 0; i < n; ++i) crc = table[(crc ^ data[i]) & 0xffu] ^ (crc >> 8);
    return ~crc;
}

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t v)
{
    for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}

void put_chunk(std::ofstream& out, const char* type, const std::vector<std::uint8_t>& data)
{
    std::vector<std::uint8_t> chunk;
    chunk.reserve(data.size() + 12);
    put_u32(chunk, static_cast<std::uint32_t>(data.size()));
    for (int k = 0; k < 4; ++k) chunk.push_back(static_cast<std::uint8_t>(type[k]));
    for (const std::uint8_t b : data) chunk.push_back(b);
    put_u32(chunk, crc32(chunk.data() + 4, chunk.size() - 4));
    out.write(reinterpret_cast<const char*>(chunk.data()), static_cast<std::streamsize>(chunk.size()));
}

/// Writes bits least significant first, as deflate packs them.
class BitWriter {
public:
    explicit BitWriter(std::vector<std::uint8_t>& out) : out_(out) {}
    void bits(std::uint32_t value, int count)
    {
        for (int k = 0; k < count; ++k) put((value >> k) & 1u);
    }
    /// A Huffman code: its bits go most significant first.
    void code(std::uint32_t value, int count)
    {
        for (int k = count - 1; k >= 0; --k) put((value >> k) & 1u);
    }
    void flush()
    {
        if (used_ > 0) out_.push_back(current_);
        current_ = 0;
        used_ = 0;
    }

private:
    void put(std::uint32_t bit)
    {
        current_ = static_cast<std::uint8_t>(current_ | (bit << used_));
        if (++used_ == 8) flush();
    }
    std::vector<std::uint8_t>& out_;
    std::uint8_t current_ = 0;
    int used_ = 0;
};

void literal_code(BitWriter& w, int symbol)
{
    if (symbol <= 143) w.code(static_cast<std::uint32_t>(0x30 + symbol), 8);
    else if (symbol <= 255) w.code(static_cast<std::uint32_t>(0x190 + symbol - 144), 9);
    else if (symbol <= 279) w.code(static_cast<std::uint32_t>(symbol - 256), 7);
    else w.code(static_cast<std::uint32_t>(0xc0 + symbol - 280), 8);
}

/// One final deflate block with fixed codes; back-references only at the given distances.
void deflate_fixed(const std::vector<std::uint8_t>& data, std::initializer_list<std::size_t> distances, std::vector<std::uint8_t>& out)
{
    static const int length_base[29] = {3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
    static const int length_extra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
    static const int distance_base[30] = {1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769,
                                          1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
    static const int distance_extra[30] = {0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};
    BitWriter w(out);
    w.bits(1, 1);  // final block
    w.bits(1, 2);  // fixed Huffman codes
    std::size_t i = 0;
    while (i < data.size()) {
        std::size_t best_length = 0, best_distance = 0;
        for (const std::size_t d : distances) {
            if (d > i || d > 32768) continue;
            std::size_t n = 0;
            while (n < 258 && i + n < data.size() && data[i + n] == data[i + n - d]) ++n;
            if (n > best_length) { best_length = n; best_distance = d; }
        }
        if (best_length < 3) {
            literal_code(w, data[i]);
            ++i;
            continue;
        }
        int lc = 28;
        while (length_base[lc] > static_cast<int>(best_length)) --lc;
        literal_code(w, 257 + lc);
        w.bits(static_cast<std::uint32_t>(static_cast<int>(best_length) - length_base[lc]), length_extra[lc]);
        int dc = 29;
        while (distance_base[dc] > static_cast<int>(best_distance)) --dc;
        w.code(static_cast<std::uint32_t>(dc), 5);
        w.bits(static_cast<std::uint32_t>(static_cast<int>(best_distance) - distance_base[dc]), distance_extra[dc]);
        i += best_length;
    }
    literal_code(w, 256);  // end of block
    w.flush();
}

}  // namespace

Rgb colour_ramp(double u)
{
    static const double stops[6][3] = {{0.05, 0.05, 0.45}, {0.0, 0.35, 1.0}, {0.0, 0.8, 0.85},
                                       {0.45, 0.9, 0.2},   {1.0, 0.8, 0.0},  {0.7, 0.0, 0.0}};
    if (!std::isfinite(u)) u = 0.0;
    u = std::clamp(u, 0.0, 1.0) * 5.0;
    const int k = std::min(4, static_cast<int>(u));
    const double f = u - k;
    const auto channel = [&](int c) {
        return static_cast<std::uint8_t>(std::lround(255.0 * (stops[k][c] * (1.0 - f) + stops[k + 1][c] * f)));
    };
    return {channel(0), channel(1), channel(2)};
}

Image::Image(int width_px, int height_px, Rgb background) : width_(width_px), height_(height_px)
{
    if (width_px <= 0 || height_px <= 0 || width_px > 20000 || height_px > 20000)
        throw InputError(concat("image size ", width_px, " x ", height_px, " px; expected 1..20000 each"));
    rgb_.resize(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 3);
    for (std::size_t i = 0; i < rgb_.size(); i += 3) {
        rgb_[i] = background.r;
        rgb_[i + 1] = background.g;
        rgb_[i + 2] = background.b;
    }
}

Rgb Image::pixel(int x, int y) const
{
    const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
    return {rgb_[i], rgb_[i + 1], rgb_[i + 2]};
}

void Image::set(int x, int y, Rgb c)
{
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
    const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * 3;
    rgb_[i] = c.r;
    rgb_[i + 1] = c.g;
    rgb_[i + 2] = c.b;
}

void Image::fill_rect(int x0, int y0, int x1, int y1, Rgb colour)
{
    for (int y = std::max(0, y0); y < std::min(height_, y1); ++y)
        for (int x = std::max(0, x0); x < std::min(width_, x1); ++x) set(x, y, colour);
}

void Image::fill_triangle(const double x[3], const double y[3], const double value[3], double lo, double hi)
{
    const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    if (area == 0.0) return;
    const int xa = std::max(0, static_cast<int>(std::floor(std::min({x[0], x[1], x[2]}))));
    const int xb = std::min(width_ - 1, static_cast<int>(std::ceil(std::max({x[0], x[1], x[2]}))));
    const int ya = std::max(0, static_cast<int>(std::floor(std::min({y[0], y[1], y[2]}))));
    const int yb = std::min(height_ - 1, static_cast<int>(std::ceil(std::max({y[0], y[1], y[2]}))));
    const double span = hi > lo ? hi - lo : 1.0;
    for (int py = ya; py <= yb; ++py)
        for (int px = xa; px <= xb; ++px) {
            const double cx = px + 0.5, cy = py + 0.5;  // pixel centre
            const double w0 = ((x[1] - cx) * (y[2] - cy) - (x[2] - cx) * (y[1] - cy)) / area;
            const double w1 = ((x[2] - cx) * (y[0] - cy) - (x[0] - cx) * (y[2] - cy)) / area;
            const double w2 = 1.0 - w0 - w1;
            const double eps = -1e-9;
            if (w0 < eps || w1 < eps || w2 < eps) continue;
            set(px, py, colour_ramp((w0 * value[0] + w1 * value[1] + w2 * value[2] - lo) / span));
        }
}

void Image::draw_text(int x, int y, const std::string& text, int scale, Rgb colour)
{
    const auto& glyphs = font();
    for (std::size_t k = 0; k < text.size(); ++k) {
        const auto it = glyphs.find(text[k]);
        if (it == glyphs.end())
            throw InputError(concat("image text '", text, "': the built-in font has no '", text[k], "'"));
        for (int row = 0; row < 7; ++row)
            for (int col = 0; col < 5; ++col)
                if (it->second[static_cast<std::size_t>(row)][col] == '#')
                    fill_rect(x + (static_cast<int>(k) * 6 + col) * scale, y + row * scale,
                              x + (static_cast<int>(k) * 6 + col + 1) * scale, y + (row + 1) * scale, colour);
    }
}

void Image::write_png(const std::string& path) const
{
    std::ofstream out(path, std::ios::binary);
    if (!out) throw InputError(concat("cannot open '", path, "' for writing"));
    const std::uint8_t signature[8] = {137, 80, 78, 71, 13, 10, 26, 10};
    out.write(reinterpret_cast<const char*>(signature), 8);

    std::vector<std::uint8_t> header;
    put_u32(header, static_cast<std::uint32_t>(width_));
    put_u32(header, static_cast<std::uint32_t>(height_));
    header.insert(header.end(), {8, 2, 0, 0, 0});  // 8 bits, RGB, deflate, no filter method, no interlace
    put_chunk(out, "IHDR", header);

    // raw scanlines, each with filter byte 0
    std::vector<std::uint8_t> raw;
    const std::size_t row = static_cast<std::size_t>(width_) * 3;
    raw.reserve((row + 1) * static_cast<std::size_t>(height_));
    for (int yy = 0; yy < height_; ++yy) {
        raw.push_back(0);
        raw.insert(raw.end(), rgb_.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(yy)),
                   rgb_.begin() + static_cast<std::ptrdiff_t>(row * static_cast<std::size_t>(yy + 1)));
    }
    // zlib stream: one deflate block with the fixed Huffman codes (RFC 1951 §3.2.6); matches are looked
    // for one pixel back and one row up, which is where a picture of flat colours repeats itself
    std::vector<std::uint8_t> z{0x78, 0x01};
    deflate_fixed(raw, {3, row + 1}, z);
    std::uint32_t a = 1, b = 0;
    for (const std::uint8_t v : raw) {
        a = (a + v) % 65521u;
        b = (b + a) % 65521u;
    }
    put_u32(z, (b << 16) | a);
    put_chunk(out, "IDAT", z);
    put_chunk(out, "IEND", {});
    out.flush();
    if (!out) throw InputError(concat("failed while writing '", path, "' (disk full?)"));
}

}  // namespace dipper::wear
