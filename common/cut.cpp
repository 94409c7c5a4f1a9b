#include "dynhet/cut.hpp"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dynhet/state_archive.hpp"

namespace dynhet {

std::string cut_dir(const std::string& root, int cut) {
  char name[32];
  std::snprintf(name, sizeof name, "cut-%06d", cut);
  return root + "/" + name;
}

std::string part_path(const std::string& root, int cut, const std::string& process, int frame) {
  if (process == "sim") return cut_dir(root, cut) + "/sim.part";
  return root + "/frames/" + process + "-" + std::to_string(frame + 1) + ".part";
}

std::vector<int> list_cuts(const std::string& root) {
  std::vector<int> cuts;
  DIR* d = opendir(root.c_str());
  if (!d) return cuts;
  while (const dirent* e = readdir(d)) {
    int n = -1;
    char tail = 0;
    if (std::sscanf(e->d_name, "cut-%d%c", &n, &tail) == 1 && n >= 0) cuts.push_back(n);
  }
  closedir(d);
  std::sort(cuts.begin(), cuts.end());
  return cuts;
}

std::vector<std::string> mark_cut_whole(const std::string& root, const CutInfo& c, uint64_t scene) {
  std::vector<std::string> bad;
  std::ostringstream text;
  text << "dynhet cut\ncut " << c.cut << "\nframe " << c.frame << "\nrun_id " << c.run_id << "\n";
  char t[64];
  std::snprintf(t, sizeof t, "%.17g", c.sim_time);
  text << "sim_time " << t << "\nbuild " << build_id() << "\n";
  for (const std::string& p : c.parts) {
    PartHeader h;
    try {
      const std::string path = part_path(root, c.cut, p, c.frame);
      check_part(path, p, c.run_id, scene, &h);
      if (h.frame != c.frame || (p == "sim" && h.cut != c.cut))
        throw BadPart(path + ": saved for cut " + std::to_string(h.cut) + " after frame " + std::to_string(h.frame) +
                      ", not cut " + std::to_string(c.cut) + " after frame " + std::to_string(c.frame));
      text << "part " << p << " " << h.crc << "\n";
    } catch (const BadPart& e) {
      bad.push_back(p + ": " + e.what());
    }
  }
  if (!bad.empty()) return bad;
  const std::string s = text.str();
  write_file_atomic(cut_dir(root, c.cut) + "/WHOLE", std::vector<uint8_t>(s.begin(), s.end()));
  return bad;
}

std::optional<CutInfo> read_cut_marker(const std::string& root, int cut) {
  std::ifstream in(cut_dir(root, cut) + "/WHOLE");
  if (!in) return std::nullopt;
  CutInfo c;
  std::string line, head;
  if (!std::getline(in, line) || line != "dynhet cut") return std::nullopt;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    s >> head;
    if (head == "cut") s >> c.cut;
    else if (head == "frame") s >> c.frame;
    else if (head == "run_id") s >> c.run_id;
    else if (head == "sim_time") s >> c.sim_time;
    else if (head == "part") {
      std::string p;
      s >> p;
      c.parts.push_back(p);
    }
  }
  if (c.cut != cut || c.parts.empty()) return std::nullopt;
  return c;
}

std::optional<CutInfo> latest_whole_cut(const std::string& root, uint64_t scene, std::vector<std::string>& refused) {
  std::vector<int> cuts = list_cuts(root);
  for (auto it = cuts.rbegin(); it != cuts.rend(); ++it) {
    const std::optional<CutInfo> c = read_cut_marker(root, *it);
    if (!c) continue; // never whole: not a cut
    try {
      for (const std::string& p : c->parts) {
        PartHeader h;
        const std::string path = part_path(root, c->cut, p, c->frame);
        check_part(path, p, c->run_id, scene, &h);
        if (h.frame != c->frame || (p == "sim" && h.cut != c->cut))
          throw BadPart(path + ": saved for another cut or frame");
      }
      return c;
    } catch (const BadPart& e) {
      refused.push_back("cut " + std::to_string(*it) + " refused: " + e.what());
    }
  }
  return std::nullopt;
}

void prune_cuts(const std::string& root, int keep_from, int keep_frame) {
  std::error_code ec;
  for (int c : list_cuts(root))
    if (c < keep_from) std::filesystem::remove_all(cut_dir(root, c), ec);
  for (const auto& e : std::filesystem::directory_iterator(root + "/frames", ec)) {
    const std::string name = e.path().filename().string();
    const auto dash = name.rfind('-');
    int f = -1;
    if (dash == std::string::npos || std::sscanf(name.c_str() + dash + 1, "%d.part", &f) != 1) continue;
    std::error_code ec2;
    if (f < keep_frame + 1) std::filesystem::remove(e.path(), ec2); // before the fallback cut's boundary
  }
}

} // namespace dynhet
