package dynhet.spy;

import dynhet.bond_breaking_t;
import javax.swing.Action;
import javax.swing.JDesktopPane;
import lcm.spy.ChannelData;
import lcm.spy.SpyPlugin;

/** lcm-spy view of bond_breaking_t (DYNHET_BOND_BREAKING): C_B(t) against the lag, with the 1/e line. */
public final class BondBreakingPlugin implements SpyPlugin {
  public boolean canHandle(long fingerprint) { return fingerprint == bond_breaking_t.LCM_FINGERPRINT; }

  public Action getAction(JDesktopPane desktop, ChannelData channel) {
    return CurveView.action("dynhet: C_B(t)", desktop, channel, BondBreakingPlugin::curves);
  }

  static Curves curves(Object message) throws Curves.BadMessage {
    Curves.need(message instanceof bond_breaking_t, "not a bond_breaking_t");
    bond_breaking_t m = (bond_breaking_t)message;
    Curves.length(m.lag_time, m.n_lags, "lag_time");
    Curves.length(m.c_b, m.n_lags, "c_b");
    Curves c = new Curves("C_B(t), bonds " + Curves.num(m.a1) + " to " + Curves.num(m.a2) + " sigma", "t", "C_B",
                          true, false);
    c.add("C_B(t)", m.lag_time, m.c_b, 0, m.n_lags);
    c.addOneOverE(m.lag_time); // tau_B is where C_B crosses it
    c.say(Curves.stamp(m.run_id, m.frame_index, m.sim_time, m.is_final) + " \u00b7 " +
          Curves.num(m.bonds_per_particle) + " bonds per particle");
    c.say("\u03c4_B = " + Curves.pm(m.tau_b, m.tau_b_err));
    return c;
  }
}
