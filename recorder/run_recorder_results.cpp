// The RunRecorder's results: one path for every result type, driven by its
// declaration (ResultDecl<T>, generated from lcmtypes/<type>.lcm): the
// checks (its run, a frame of the run, its arrays' shapes), its group's
// attributes, axes and record, and the final result completion waits for.
#include "run_recorder.hpp"

#include "result_group.hpp"
#include "run_recorder_util.hpp"

namespace dynhet {

using namespace recorder_util;

template <class T> bool RunRecorder::on_result(const T &m) {
  using D = ResultDecl<T>;
  if (!info_ || m.run_id != info_->run_id) return false;
  std::string bad = frame_problem(m.frame_index);
  if (bad.empty()) bad = D::size_problem(m);
  if (!bad.empty()) return rejected(result_channel_of(m), bad);
  guarded(D::name, [&] { write_result(m); });
  if (m.is_final) completion_.final_result(result_group(D::name, D::cage_relative(m)), D::cutoff(m));
  return true;
}

// observables/<name>[_cr][/a<cutoff>]/: the attributes with the group, each
// axis the first time a message has it, then the record at the message's
// frame (none before the first frame is folded in, frame_index -1).
template <class T> void RunRecorder::write_result(const T &m) {
  using D = ResultDecl<T>;
  std::string base = result_group(D::name, D::cage_relative(m)) + "/";
  if (D::per_cutoff) base += cutoff_label(D::cutoff(m)) + "/";
  ResultGroup g(*writer_, started_, base);
  if (started_.insert(base).second) {
    D::attributes(g, m);
    if (D::cage_relative(m)) g.attr("displacements", kCageRelative);
  }
  D::axes(g, m);
  if (!D::has_record(m) || m.frame_index < 0) return;
  g.at(*at_frame(m.frame_index, m.is_final));
  D::record(g, m);
}

#define DYNHET_ON_RESULT(T) template bool RunRecorder::on_result<T>(const T &);
DYNHET_RESULT_TYPES(DYNHET_ON_RESULT)
#undef DYNHET_ON_RESULT

} // namespace dynhet
