package dynhet.spy;

import dynhet.msd_t;
import javax.swing.Action;
import javax.swing.JDesktopPane;
import lcm.spy.ChannelData;
import lcm.spy.SpyPlugin;

/**
 * lcm-spy view of msd_t (DYNHET_MSD): the MSD of all and of the small
 * particles, and of the instantaneous fastest and slowest subsets, log-log.
 */
public final class MsdPlugin implements SpyPlugin {
  public boolean canHandle(long fingerprint) { return fingerprint == msd_t.LCM_FINGERPRINT; }

  public Action getAction(JDesktopPane desktop, ChannelData channel) {
    return CurveView.action("dynhet: MSD(t)", desktop, channel, MsdPlugin::curves);
  }

  static String percent(double fraction) { return Curves.num(100 * fraction) + "%"; }

  static Curves curves(Object message) throws Curves.BadMessage {
    Curves.need(message instanceof msd_t, "not an msd_t");
    msd_t m = (msd_t)message;
    int n = m.n_lags;
    Curves.length(m.lag_time, n, "lag_time");
    Curves c = new Curves("MSD(t)" + Curves.cageRelative(m.cage_relative), "t", "MSD", true, true);
    String all = percent(m.fraction_all), small = percent(m.fraction_small);
    Object[][] series = {{"all", m.msd_all},
                         {"small", m.msd_small},
                         {"fastest " + all + " of all", m.msd_fast_all},
                         {"slowest " + all + " of all", m.msd_slow_all},
                         {"fastest " + small + " of small", m.msd_fast_small},
                         {"slowest " + small + " of small", m.msd_slow_small}};
    for (Object[] s : series) {
      Curves.length((double[])s[1], n, (String)s[0]);
      c.add((String)s[0], m.lag_time, (double[])s[1], 0, n);
    }
    c.say(Curves.stamp(m.run_id, m.frame_index, m.sim_time, m.is_final));
    c.say("D = " + Curves.pm(m.diffusion, m.diffusion_err) + " (MSD = 4Dt + b over t in [" +
          Curves.num(m.fit_t_min) + ", " + Curves.num(m.fit_t_max) + "])");
    return c;
  }
}
