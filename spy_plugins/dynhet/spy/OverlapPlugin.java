package dynhet.spy;

import dynhet.overlap_t;
import javax.swing.Action;
import javax.swing.JDesktopPane;
import lcm.spy.ChannelData;
import lcm.spy.SpyPlugin;

/** lcm-spy view of overlap_t (DYNHET_OVERLAP_<a>): Q(t) against the lag, with the 1/e line. */
public final class OverlapPlugin implements SpyPlugin {
  public boolean canHandle(long fingerprint) { return fingerprint == overlap_t.LCM_FINGERPRINT; }

  public Action getAction(JDesktopPane desktop, ChannelData channel) {
    return CurveView.action("dynhet: Q(t)", desktop, channel, OverlapPlugin::curves);
  }

  static Curves curves(Object message) throws Curves.BadMessage {
    Curves.need(message instanceof overlap_t, "not an overlap_t");
    overlap_t m = (overlap_t)message;
    Curves.length(m.lag_time, m.n_lags, "lag_time");
    Curves.length(m.q, m.n_lags, "q");
    Curves.length(m.n_origins, m.n_lags, "n_origins");
    Curves c = new Curves("Q(t), a = " + Curves.num(m.cutoff_a) + Curves.cageRelative(m.cage_relative), "t", "Q", true,
                          false);
    c.add("Q(t)", m.lag_time, m.q, 0, m.n_lags);
    c.addOneOverE(m.lag_time); // tau_alpha is where Q crosses it
    int origins = m.n_lags > 0 ? m.n_origins[0] : 0;
    c.say("a = " + Curves.num(m.cutoff_a) + " \u00b7 " +
          Curves.stamp(m.run_id, m.frame_index, m.sim_time, m.is_final) + " \u00b7 " + origins +
          " origins at the first lag");
    c.say("\u03c4\u03b1 = " + Curves.pm(m.tau_alpha, m.tau_alpha_err) +
          " \u00b7 fit 1/((t/\u03c40)^\u03b2 + 1): \u03c40 = " + Curves.pm(m.tau0, m.tau0_err) +
          ", \u03b2 = " + Curves.pm(m.beta, m.beta_err));
    return c;
  }
}
