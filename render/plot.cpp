#include "render/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace softtled {

void nice_range(double& lo, double& hi, double& step, int n) {
  if (!(hi > lo)) {
    const double d = lo != 0 ? 0.1 * std::fabs(lo) : 1.0;
    lo -= d, hi += d;
  }
  const double raw = (hi - lo) / std::max(1, n);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / mag;
  step = (f <= 1 ? 1 : f <= 2 ? 2 : f <= 5 ? 5 : 10) * mag;
  // A hair of slack so that data exactly on a tick is not pushed a whole step out.
  lo = std::floor(lo / step + 1e-9) * step;
  hi = std::ceil(hi / step - 1e-9) * step;
}

namespace {
struct Canvas {
  Image im;
  void fill(double x0, double y0, double x1, double y1, Vec3 c, float alpha = 1) {
    const int a = std::max(0, int(std::floor(x0))), b = std::min(im.w, int(std::ceil(x1)));
    const int p = std::max(0, int(std::floor(y0))), q = std::min(im.h, int(std::ceil(y1)));
    for (int y = p; y < q; ++y)
      for (int x = a; x < b; ++x) {
        std::uint8_t* px = im.px(x, y);
        for (int k = 0; k < 3; ++k)
          px[k] = std::uint8_t(std::lround((1 - alpha) * px[k] + alpha * 255.f * std::clamp(c[k], 0.f, 1.f)));
      }
  }
  // A line of width `lw` px: squares stamped every quarter pixel along it.
  void line(double xa, double ya, double xb, double yb, double lw, Vec3 c) {
    const double len = std::hypot(xb - xa, yb - ya);
    const int n = std::max(1, int(std::ceil(len * 4)));
    for (int i = 0; i <= n; ++i) {
      const double t = double(i) / n, x = xa + t * (xb - xa), y = ya + t * (yb - ya);
      fill(std::round(x - lw / 2), std::round(y - lw / 2), std::round(x - lw / 2) + lw, std::round(y - lw / 2) + lw, c);
    }
  }
  void text(const std::string& s, double x, double y, float scale, Vec3 c) {
    std::vector<TextRect> r;
    text_rects(s, float(x), float(y), scale, r);
    for (const TextRect& q : r) fill(q.x0, q.y0, q.x1, q.y1, c);
  }
};

}  // namespace

std::string plot_tick_text(double v, double step) {
  if (std::fabs(v) < 1e-9 * step) v = 0;
  char buf[64];
  const double mag = std::max(std::fabs(v), step);
  const int e_step = int(std::floor(std::log10(step) + 1e-9));
  if (step >= 1e-4 && mag < 1e7) {
    std::snprintf(buf, sizeof buf, "%.*f", std::clamp(-e_step, 0, 4), v);
    return buf;
  }
  // Beyond that a fixed decimal read 0.000000000 for every tick of a sub-nanojoule energy
  // axis, or 30 noisy digits at 1e27: the mantissa carries as many digits as tell the
  // ticks apart.
  if (v == 0) return "0";
  // (12: an axis offset by 1e12 steps from zero, a resting centroid's column, still reads.)
  const int digits = std::clamp(int(std::floor(std::log10(mag))) - e_step, 0, 12);
  std::snprintf(buf, sizeof buf, "%.*e", digits, v);
  return buf;
}

Image plot_panels(const std::vector<PlotPanel>& panels, int w, int h, std::vector<PlotAxes>* axes_out) {
  Canvas cv{Image(w, h)};
  for (std::size_t i = 0; i < cv.im.rgba.size(); ++i) cv.im.rgba[i] = 255;
  if (axes_out) axes_out->clear();
  if (panels.empty()) return cv.im;
  const float s = float(std::max(1, std::min(w, h) / 350));
  const double th = text_height(s), lw = std::max(1.0, std::round(1.5 * s));
  const Vec3 ink{0.1f, 0.1f, 0.12f}, grid{0.88f, 0.89f, 0.91f}, dim{0.35f, 0.36f, 0.40f};
  const double slot = double(h) / double(panels.size());
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const PlotPanel& pn = panels[p];
    PlotAxes ax;
    double xlo = 1e300, xhi = -1e300, ylo = 1e300, yhi = -1e300;
    for (const PlotSeries& sr : pn.series)
      for (std::size_t k = 0; k < std::min(sr.x.size(), sr.y.size()); ++k) {
        if (!std::isfinite(sr.x[k]) || !std::isfinite(sr.y[k])) continue;
        xlo = std::min(xlo, sr.x[k]), xhi = std::max(xhi, sr.x[k]);
        ylo = std::min(ylo, sr.y[k]), yhi = std::max(yhi, sr.y[k]);
      }
    if (xlo > xhi) xlo = 0, xhi = 1, ylo = 0, yhi = 1;
    double xstep = 1, ystep = 1;
    nice_range(xlo, xhi, xstep);
    nice_range(ylo, yhi, ystep);
    ax.x0 = xlo, ax.x1 = xhi, ax.y0 = ylo, ax.y1 = yhi;
    const int nx = int(std::lround((xhi - xlo) / xstep)), ny = int(std::lround((yhi - ylo) / ystep));
    double label_w = 0;
    for (int k = 0; k <= ny; ++k) label_w = std::max(label_w, double(text_width(plot_tick_text(ylo + k * ystep, ystep), s)));
    // The key (one entry per series) goes right-aligned on the title's line, or on a line of
    // its own under the title where the two would overlap (they did on the energy panel).
    double key_w = 0;
    if (pn.series.size() > 1)
      for (const PlotSeries& sr : pn.series) key_w += text_width(sr.name, s) + 33 * s;
    const double x0 = std::round(12 * s + label_w + 6 * s), x1 = w - std::round(16 * s);
    const double key_line = text_width(pn.title, s) + 12 * s + key_w > x1 - x0 ? th + 6 * s : 0;
    const double top = std::round(p * slot + 10 * s + th + 8 * s + key_line), bottom = std::round((p + 1) * slot - 2 * th - 14 * s);
    ax.frame = {float(x0), float(top), float(x1), float(bottom)};
    const TextRect& f = ax.frame;
    // Grid and tick values.
    for (int k = 0; k <= nx; ++k) {
      const double v = xlo + k * xstep, x = std::round(ax.px(v));
      cv.fill(x, f.y0, x + 1, f.y1, grid);
      const std::string t = plot_tick_text(v, xstep);
      const double tw = text_width(t, s);  // centred on its tick, within the image
      cv.text(t, std::clamp(x - tw / 2, 0.0, std::max(0.0, w - 2 * s - tw)), f.y1 + 5 * s, s, ink);
    }
    for (int k = 0; k <= ny; ++k) {
      const double v = ylo + k * ystep, y = std::round(ax.py(v));
      cv.fill(f.x0, y, f.x1, y + 1, grid);
      const std::string t = plot_tick_text(v, ystep);
      cv.text(t, f.x0 - 6 * s - text_width(t, s), y - th / 2, s, ink);
    }
    // The curves, clipped to the frame (the data lies inside by construction).
    for (const PlotSeries& sr : pn.series) {
      bool have = false;
      double xa = 0, ya = 0;
      for (std::size_t k = 0; k < std::min(sr.x.size(), sr.y.size()); ++k) {
        if (!std::isfinite(sr.x[k]) || !std::isfinite(sr.y[k])) {
          have = false;
          continue;
        }
        const double xb = ax.px(sr.x[k]), yb = ax.py(sr.y[k]);
        if (have) cv.line(xa, ya, xb, yb, lw, sr.color);
        else cv.line(xb, yb, xb, yb, lw, sr.color);
        xa = xb, ya = yb, have = true;
      }
    }
    // Frame, title, x label, key (top right, inside the frame).
    cv.fill(f.x0, f.y0, f.x1, f.y0 + 1, ink), cv.fill(f.x0, f.y1, f.x1, f.y1 + 1, ink);
    cv.fill(f.x0, f.y0, f.x0 + 1, f.y1 + 1, ink), cv.fill(f.x1, f.y0, f.x1 + 1, f.y1 + 1, ink);
    cv.text(pn.title, f.x0, f.y0 - th - 6 * s - key_line, s, ink);
    cv.text(pn.xlabel, (f.x0 + f.x1) / 2 - text_width(pn.xlabel, s) / 2, f.y1 + th + 10 * s, s, dim);
    // The key, right-aligned above the frame (never over the data).
    if (pn.series.size() > 1) {
      double kx = f.x1;
      const double ky = f.y0 - th - 6 * s;
      for (auto it = pn.series.rbegin(); it != pn.series.rend(); ++it) {
        kx -= text_width(it->name, s);
        cv.text(it->name, kx, ky, s, ink);
        kx -= 5 * s + 14 * s;
        cv.fill(kx, std::round(ky + th / 2 - lw / 2), kx + 14 * s, std::round(ky + th / 2 - lw / 2) + lw, it->color);
        kx -= 14 * s;
      }
    }
    if (axes_out) axes_out->push_back(ax);
  }
  return cv.im;
}

}  // namespace softtled
