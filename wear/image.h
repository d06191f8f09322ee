// A small RGB raster for wear-map pictures: filled triangles with interpolated colour, rectangles, a
// built-in 5x7 pixel font for numbers and units, and a PNG writer (deflate with fixed codes, no dependency).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace dipper::wear {

struct Rgb {
    std::uint8_t r = 255, g = 255, b = 255;
};

/// A colour ramp from dark blue (0) through cyan, green and yellow to dark red (1); u is clamped to [0, 1].
Rgb colour_ramp(double u);

class Image {
public:
    Image(int width_px, int height_px, Rgb background = {});
    int width() const { return width_; }
    int height() const { return height_; }
    Rgb pixel(int x, int y) const;
    void set(int x, int y, Rgb colour);  ///< outside the image: ignored
    void fill_rect(int x0, int y0, int x1, int y1, Rgb colour);  ///< [x0, x1) x [y0, y1)
    /// Fills a triangle (pixel coordinates) with the ramp colour of a value interpolated linearly from its
    /// corners, mapped from [lo, hi] to [0, 1].
    void fill_triangle(const double x[3], const double y[3], const double value[3], double lo, double hi);
    /// Text in the built-in font (digits, . - + e m / t w a r ( ) and space; anything else is an error),
    /// top-left corner at (x, y), each font pixel drawn as scale x scale.
    void draw_text(int x, int y, const std::string& text, int scale, Rgb colour);
    static int text_width(const std::string& text, int scale) { return static_cast<int>(text.size()) * 6 * scale; }
    /// Writes a PNG (8-bit RGB). Throws InputError naming the path if it cannot.
    void write_png(const std::string& path) const;

private:
    int width_, height_;
    std::vector<std::uint8_t> rgb_;
};

}  // namespace dipper::wear
