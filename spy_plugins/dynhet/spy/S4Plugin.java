package dynhet.spy;

import dynhet.s4_t;
import javax.swing.Action;
import javax.swing.JDesktopPane;
import lcm.spy.ChannelData;
import lcm.spy.SpyPlugin;

/** lcm-spy view of s4_t (DYNHET_S4_<a>): S4(q) at t_s4 (= tau_alpha, between lags) on every sub-box grid, log-log. */
public final class S4Plugin implements SpyPlugin {
  public boolean canHandle(long fingerprint) { return fingerprint == s4_t.LCM_FINGERPRINT; }

  public Action getAction(JDesktopPane desktop, ChannelData channel) {
    return CurveView.action("dynhet: S4(q)", desktop, channel, S4Plugin::curves);
  }

  static Curves curves(Object message) throws Curves.BadMessage {
    Curves.need(message instanceof s4_t, "not an s4_t");
    s4_t m = (s4_t)message;
    Curves.need(m.n_grids >= 0 && m.n_grids <= Curves.MAX_SERIES, "n_grids " + m.n_grids);
    Curves.length(m.subbox_particles, m.n_grids, "subbox_particles");
    Curves.length(m.subbox_per_side, m.n_grids, "subbox_per_side");
    Curves.length(m.n_shells, m.n_grids, "n_shells");
    // Grid g's shells follow grid g-1's: offsets are sums of n_shells.
    long total = 0;
    for (int s : m.n_shells) {
      Curves.need(s >= 0, "n_shells < 0");
      total += s;
    }
    Curves.need(total == m.n_values, "n_values is not the sum of n_shells");
    Curves.length(m.q, m.n_values, "q");
    Curves.length(m.s4, m.n_values, "s4");
    Curves c = new Curves("S4(q) at t = " + Curves.num(m.t_s4) + ", a = " + Curves.num(m.cutoff_a) +
                              Curves.cageRelative(m.cage_relative), "q", "S4",
                          true, true);
    int offset = 0;
    for (int g = 0; g < m.n_grids; ++g) {
      double[] q = new double[m.n_shells[g]];
      System.arraycopy(m.q, offset, q, 0, q.length);
      c.add(Chi4Plugin.gridName(m.subbox_per_side[g], m.subbox_particles[g]), q, m.s4, offset, q.length);
      offset += m.n_shells[g];
    }
    c.say("a = " + Curves.num(m.cutoff_a) + " \u00b7 " +
          Curves.stamp(m.run_id, m.frame_index, m.sim_time, m.is_final) +
          " \u00b7 t_s4 = " + Curves.num(m.t_s4) + " (\u03c4\u03b1 " + Curves.num(m.tau_alpha) + "), " +
          m.n_origins + " origins");
    c.say("whole box: \u03be = " + Curves.pm(m.xi, m.xi_err) + ", \u03c70 = " +
          Curves.pm(m.chi0, m.chi0_err) + ", \u03c74 = " + Curves.pm(m.chi4_box, m.chi4_box_err));
    return c;
  }
}
