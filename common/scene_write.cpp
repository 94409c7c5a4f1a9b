// A scene written out from the description of its keys (scene_keys.cpp):
// the resolved scene as TOML and the reference of every key.
#include "dynhet/scene.hpp"

#include "dynhet/model.hpp"
#include "dynhet/schedule.hpp"
#include "scene_keys.hpp"

namespace dynhet {
using namespace scene_detail;

std::string scene_toml(const Scene& s) {
  std::string out, table;
  for (const SceneKey& k : scene_keys()) {
    const std::string v = k.write(s);
    if (v.empty()) continue;
    if (k.table != table) {
      out += (out.empty() ? "[" : "\n[") + k.table + "]\n";
      table = k.table;
    }
    out += k.key + " = " + v + "\n";
  }
  return out;
}

std::string model_toml(const Scene& s) {
  const Model m = make_model(s.n_particles, s.packing_fraction, s.radius_ratio);
  const double g_c = scene_contact_value(s);
  auto pair = [](const double v[2]) { return "[" + toml_float(v[0]) + ", " + toml_float(v[1]) + "]"; };
  const FrameSchedule sched = make_schedule(s.schedule, s.equilibration_time);
  std::string t = "[model]\n";
  t += "radius = " + pair(m.radius) + "\n";
  t += "mass = " + pair(m.mass) + "\n";
  t += "n_small = " + std::to_string(small_count(s.n_particles)) + "\n";
  t += "box_length = " + toml_float(m.box_length) + "\n";
  t += "contact_value = " + toml_float(g_c) + "\n";
  t += "collision_frequency = " + toml_float(enskog_frequency(s.packing_fraction, g_c)) + "\n";
  t += "kick_rate = " + toml_float(scene_kick_rate(s)) + "\n";
  t += "kick_amplitude = " + toml_float(kick_amplitude(s.restitution, m.mass[0], m.mass[1])) + "\n";
  t += "frames = " + std::to_string(sched.frame_time.size()) + "\n";
  t += "sim_time = " + toml_float(s.equilibration_time + s.production_time) + "\n";
  return t;
}

namespace {
// Text in a Markdown table cell: its pipes escaped (|dr| < a).
std::string cell(const std::string& text) {
  std::string t;
  for (char ch : text) t += ch == '|' ? std::string("\\|") : std::string(1, ch);
  return t;
}
} // namespace

std::string scene_reference_markdown() {
  const Scene defaults;
  std::string out, table;
  for (const SceneKey& k : scene_keys()) {
    if (k.table != table) {
      out += (out.empty() ? "" : "\n") + ("### [" + k.table + "]\n\n") + "| key | default | allowed | meaning |\n" +
             "|---|---|---|---|\n";
      table = k.table;
    }
    const std::string v = k.default_text.empty() ? "`" + k.write(defaults) + "`" : k.default_text;
    out += "| `" + k.key + "` | " + cell(v) + " | " + cell(k.allowed) + " | " + cell(k.meaning) + " |\n";
  }
  return out;
}

std::vector<std::string> scene_key_names() {
  std::vector<std::string> names;
  for (const SceneKey& k : scene_keys()) names.push_back(k.table + "." + k.key);
  return names;
}

} // namespace dynhet
