package dynhet.spy;

import dynhet.chi4_t;
import javax.swing.Action;
import javax.swing.JDesktopPane;
import lcm.spy.ChannelData;
import lcm.spy.SpyPlugin;

/** lcm-spy view of chi4_t (DYNHET_CHI4_<a>): chi4(t) of every sub-box size, log-log. */
public final class Chi4Plugin implements SpyPlugin {
  public boolean canHandle(long fingerprint) { return fingerprint == chi4_t.LCM_FINGERPRINT; }

  public Action getAction(JDesktopPane desktop, ChannelData channel) {
    return CurveView.action("dynhet: chi4(t)", desktop, channel, Chi4Plugin::curves);
  }

  /** The curve name of grid g: its mean particles per sub-box, or the whole box. */
  static String gridName(int perSide, double particles) {
    return perSide == 1 ? "whole box" : "N_r = " + Curves.num(particles);
  }

  static Curves curves(Object message) throws Curves.BadMessage {
    Curves.need(message instanceof chi4_t, "not a chi4_t");
    chi4_t m = (chi4_t)message;
    Curves.need(m.n_grids >= 0 && m.n_grids <= Curves.MAX_SERIES, "n_grids " + m.n_grids);
    Curves.length(m.subbox_particles, m.n_grids, "subbox_particles");
    Curves.length(m.subbox_per_side, m.n_grids, "subbox_per_side");
    Curves.length(m.chi4_peak, m.n_grids, "chi4_peak");
    Curves.length(m.tau4, m.n_grids, "tau4");
    Curves.length(m.lag_time, m.n_lags, "lag_time");
    // Flat [g * n_lags + j].
    Curves.need((long)m.n_values == (long)m.n_grids * m.n_lags, "n_values is not n_grids x n_lags");
    Curves.length(m.chi4, m.n_values, "chi4");
    Curves c = new Curves("chi4(t), a = " + Curves.num(m.cutoff_a) + Curves.cageRelative(m.cage_relative), "t",
                          "chi4", true, true);
    StringBuilder peaks = new StringBuilder("peaks \u03c74^P at \u03c44:");
    for (int g = 0; g < m.n_grids; ++g) {
      String name = gridName(m.subbox_per_side[g], m.subbox_particles[g]);
      c.add(name, m.lag_time, m.chi4, g * m.n_lags, m.n_lags);
      peaks.append(g == 0 ? " " : "; ")
          .append(name)
          .append(": ")
          .append(Curves.num(m.chi4_peak[g]))
          .append(" at ")
          .append(Curves.num(m.tau4[g]));
    }
    c.say("a = " + Curves.num(m.cutoff_a) + " \u00b7 " +
          Curves.stamp(m.run_id, m.frame_index, m.sim_time, m.is_final));
    c.say(peaks.toString());
    return c;
  }
}
