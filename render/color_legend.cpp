#include "render/color_legend.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace softtled {

std::string legend_number(double v, double min, double max) {
  const double m = std::max(std::fabs(min), std::fabs(max));
  // (log10 nudged up by 1e-6, more than a float's rounding: its 0.1 is 0.0999999975 and
  // would have been given a fifth decimal, "0.10000")
  const int decimals =
      m > 0 && std::isfinite(m) ? std::clamp(3 - int(std::floor(std::log10(m) + 1e-6)), 0, 6) : 3;
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  std::string s = buf;
  if (s.find_first_not_of("-0.") == std::string::npos && s[0] == '-') s.erase(0, 1);  // no "-0.000"
  return s;
}

LegendLayout legend_layout(const ColorLegend& lg, int w, int h) {
  LegendLayout L;
  if (lg.map == LegendMap::kNone) return L;
  const float s = float(std::max(1, h / 300));
  L.scale = s;
  const float pad = 6 * s, th = text_height(s), margin = 10 * s;
  const std::string title = lg.unit.empty() ? lg.title : lg.title + " [" + lg.unit + "]";
  float content_w = text_width(title, s);
  float y = margin + pad;  // top of the next line, relative to the panel's top = margin
  std::vector<LegendLayout::Label> rel;  // x relative to the content's left edge
  rel.push_back({title, 0, y, false});
  y += th + 4 * s;
  if (lg.map == LegendMap::kTurbo) {
    const std::string sub = lg.component.empty() ? lg.colormap
                            : lg.colormap.empty() ? lg.component : lg.component + ", " + lg.colormap;
    if (!sub.empty()) {
      rel.push_back({sub, 0, y, true});
      content_w = std::max(content_w, text_width(sub, s));
      y += th + 4 * s;
    }
    const float bar_w = 12 * s;
    const float bar_h = std::round(std::max(20.f * s, std::min(0.42f * float(h), float(h) - y - th - pad - 2 * margin)));
    const float bar_top = std::round(y + th / 2);
    constexpr int kTicks = 5;
    float label_w = 0;
    for (int k = 0; k < kTicks; ++k) {
      const double v = lg.min + (lg.max - lg.min) * double(k) / (kTicks - 1);
      const float ty = bar_top + bar_h * (1 - float(k) / (kTicks - 1));
      const std::string text = legend_number(v, lg.min, lg.max);
      label_w = std::max(label_w, text_width(text, s));
      L.tick_values.push_back(v);
      L.ticks.push_back({bar_w, std::round(ty - s / 2), bar_w + 4 * s, std::round(ty - s / 2) + s});
      rel.push_back({text, bar_w + 8 * s, std::round(ty - th / 2), false});
    }
    content_w = std::max(content_w, bar_w + 8 * s + label_w);
    L.bar = {0, bar_top, bar_w, bar_top + bar_h};
    y = bar_top + bar_h + th / 2 + pad;
  } else {
    const float box = 9 * s, row = 13 * s;
    for (std::size_t k = 0; k < lg.categories.size(); ++k) {
      L.swatches.push_back({0, y, box, y + box});
      rel.push_back({lg.categories[k], box + 5 * s, y + std::round((box - th) / 2), false});
      content_w = std::max(content_w, box + 5 * s + text_width(lg.categories[k], s));
      y += row;
    }
    y += pad - (row - box);
  }
  // Place the content: the panel's right edge `margin` from the frame's.
  const float x0 = std::round(float(w) - margin - pad - content_w);
  L.panel = {x0 - pad, margin, x0 + content_w + pad, y};
  auto shift = [&](TextRect& r) { r.x0 += x0, r.x1 += x0; };
  shift(L.bar);
  for (TextRect& r : L.ticks) shift(r);
  for (TextRect& r : L.swatches) shift(r);
  for (LegendLayout::Label& l : rel) l.x += x0;
  L.labels = std::move(rel);
  return L;
}

LegendRenderer::LegendRenderer() : prog_("overlay.vert", "overlay.frag") {
  glGenVertexArrays(1, &vao_);
  glBindVertexArray(vao_);
  glGenBuffers(1, &vbo_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 1, GL_FLOAT, GL_FALSE, 3 * sizeof(float), reinterpret_cast<void*>(2 * sizeof(float)));
  glBindVertexArray(0);
  check_gl("creating the legend renderer");
}

LegendRenderer::~LegendRenderer() {
  glDeleteBuffers(1, &vbo_);
  glDeleteVertexArrays(1, &vao_);
}

namespace {
// Two triangles; the value runs from v_bottom at y1 to v_top at y0.
void push_rect(std::vector<float>& out, const TextRect& r, float v_bottom = 0, float v_top = 0) {
  const float q[6][3] = {{r.x0, r.y1, v_bottom}, {r.x1, r.y1, v_bottom}, {r.x1, r.y0, v_top},
                         {r.x0, r.y1, v_bottom}, {r.x1, r.y0, v_top},    {r.x0, r.y0, v_top}};
  for (const auto& v : q) out.insert(out.end(), v, v + 3);
}
TextRect grown(const TextRect& r, float d) { return {r.x0 - d, r.y0 - d, r.x1 + d, r.y1 + d}; }
}  // namespace

void LegendRenderer::draw(const ColorLegend& lg, int w, int h) {
  if (lg.map == LegendMap::kNone || w <= 0 || h <= 0) return;
  const LegendLayout L = legend_layout(lg, w, h);
  glViewport(0, 0, w, h);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_STENCIL_TEST);
  glDisable(GL_CULL_FACE);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  prog_.use();
  const float viewport[2] = {float(w), float(h)};
  glUniform2fv(prog_.loc("u_viewport"), 1, viewport);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  auto flush = [&](int mode, const float* color) {
    if (verts_.empty()) return;
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(verts_.size() * sizeof(float)), verts_.data(), GL_STREAM_DRAW);
    prog_.set("u_mode", mode);
    if (color) prog_.set4("u_color", color);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(verts_.size() / 3));
    verts_.clear();
  };
  const float panel_c[4] = {1.f, 1.f, 1.f, 0.72f}, ink[4] = {0.08f, 0.09f, 0.11f, 1.f}, dim[4] = {0.35f, 0.37f, 0.42f, 1.f};
  // Panel, then the dark frame around the bar or each swatch.
  push_rect(verts_, L.panel);
  flush(0, panel_c);
  if (lg.map == LegendMap::kTurbo) push_rect(verts_, grown(L.bar, L.scale));
  for (const TextRect& r : L.swatches) push_rect(verts_, grown(r, L.scale));
  flush(0, ink);
  // The colours: the bar from 0 (bottom) to 1 (top) through turbo(), state k's swatch.
  if (lg.map == LegendMap::kTurbo) {
    push_rect(verts_, L.bar, 0.f, 1.f);
    flush(1, nullptr);
  }
  for (std::size_t k = 0; k < L.swatches.size(); ++k) push_rect(verts_, L.swatches[k], float(k), float(k));
  flush(2, nullptr);
  // Ticks and text.
  for (const TextRect& r : L.ticks) push_rect(verts_, r);
  std::vector<TextRect> rects;
  for (int pass = 0; pass < 2; ++pass) {
    for (const LegendLayout::Label& l : L.labels) {
      if (l.dim != (pass == 1)) continue;
      rects.clear();
      text_rects(l.text, l.x, l.y, L.scale, rects);
      for (const TextRect& r : rects) push_rect(verts_, r);
    }
    flush(0, pass == 0 ? ink : dim);
  }
  glBindVertexArray(0);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
}

}  // namespace softtled
