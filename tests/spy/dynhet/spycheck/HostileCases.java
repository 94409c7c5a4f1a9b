package dynhet.spycheck;

import static dynhet.spycheck.ExpectedCurves.*;
import static dynhet.spycheck.SpyLog.*;
import static dynhet.spycheck.SpyPluginCheck.*;

import dynhet.bond_breaking_t;
import dynhet.chi4_t;
import dynhet.msd_t;
import dynhet.overlap_t;
import dynhet.s4_t;
import dynhet.spy.BondBreakingPlugin;
import dynhet.spy.Chi4Plugin;
import dynhet.spy.CurveView;
import dynhet.spy.MsdPlugin;
import dynhet.spy.OverlapPlugin;
import dynhet.spy.S4Plugin;
import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;
import java.util.Map;
import java.util.concurrent.atomic.AtomicReference;
import lcm.spy.ChannelData;
import lcm.spy.SpyPlugin;

/** SpyPluginCheck's part 3: hostile messages, each rejected and counted or drawn without its bad points. */
final class HostileCases {
  private HostileCases() {}

  // 3. Hostile messages.

  static void hostile(Map<String, List<Object>> log) throws Exception {
    overlap_t q = (overlap_t)last(log, "DYNHET_OVERLAP_a0.6");
    chi4_t c = (chi4_t)last(log, "DYNHET_CHI4_a0.6");
    msd_t m = (msd_t)last(log, "DYNHET_MSD");
    s4_t s = (s4_t)last(log, "DYNHET_S4_a0.6");
    if (q == null || c == null || m == null || s == null) {
      check(false, "the log has a message of each type for the hostile cases");
      return;
    }
    int n = q.n_lags;
    List<Object[]> cases = new ArrayList<>(); // name, message, rejected?
    overlap_t o;
    o = q.copy();
    o.n_lags = n + 1;
    cases.add(new Object[] {"overlap: n_lags 1 more than its arrays", o, true});
    o = q.copy();
    o.q = Arrays.copyOf(q.q, n - 1);
    cases.add(new Object[] {"overlap: q 1 short", o, true});
    o = q.copy();
    o.q = null;
    cases.add(new Object[] {"overlap: q missing", o, true});
    o = q.copy();
    o.n_lags = -1;
    cases.add(new Object[] {"overlap: n_lags -1", o, true});
    o = q.copy();
    o.lag_time[0] = Double.NaN;
    o.q[1] = Double.POSITIVE_INFINITY;
    o.q[2] = Double.NaN;
    o.lag_time[3] = -1;
    cases.add(new Object[] {"overlap: NaN, inf and a negative lag", o, false});
    o = q.copy();
    o.n_lags = 0;
    o.lag_time = new double[0];
    o.q = new double[0];
    o.q_err = new double[0];
    o.n_origins = new int[0];
    o.qr_var = new double[0];
    cases.add(new Object[] {"overlap: no lags", o, false});
    cases.add(new Object[] {"overlap view: an object of another type", "not a message", true});
    runCases(new OverlapPlugin(), "DYNHET_OVERLAP_a0.6", q, cases);

    cases.clear();
    chi4_t x;
    x = c.copy();
    x.n_values = c.n_values - 1;
    x.chi4 = Arrays.copyOf(c.chi4, c.n_values - 1);
    cases.add(new Object[] {"chi4: n_values not n_grids x n_lags", x, true});
    x = c.copy();
    x.n_grids = 1000;
    x.subbox_particles = new double[1000];
    x.subbox_per_side = new int[1000];
    x.chi4_peak = new double[1000];
    x.tau4 = new double[1000];
    cases.add(new Object[] {"chi4: 1000 grids", x, true});
    x = c.copy();
    x.n_grids = Integer.MAX_VALUE;
    cases.add(new Object[] {"chi4: n_grids 2^31-1", x, true});
    x = c.copy();
    x.chi4 = null;
    cases.add(new Object[] {"chi4: chi4 missing", x, true});
    x = c.copy();
    x.chi4[0] = 0;
    x.chi4[1] = -3;
    x.chi4[2] = Double.NaN;
    x.lag_time[4] = 0;
    cases.add(new Object[] {"chi4: 0, negative and NaN on a log axis", x, false});
    x = c.copy();
    x.n_lags = 0;
    x.lag_time = new double[0];
    x.n_values = 0;
    x.chi4 = new double[0];
    x.chi4_err = new double[0];
    cases.add(new Object[] {"chi4: no lags", x, false});
    runCases(new Chi4Plugin(), "DYNHET_CHI4_a0.6", c, cases);

    cases.clear();
    msd_t d;
    d = m.copy();
    d.msd_slow_small = Arrays.copyOf(m.msd_slow_small, m.n_lags - 1);
    cases.add(new Object[] {"msd: one array 1 short", d, true});
    d = m.copy();
    d.lag_time = null;
    cases.add(new Object[] {"msd: lag_time missing", d, true});
    d = m.copy();
    d.msd_all[0] = -1;
    d.msd_small[1] = Double.NEGATIVE_INFINITY;
    d.fraction_all = Double.NaN;
    cases.add(new Object[] {"msd: negative, -inf, NaN fraction", d, false});
    runCases(new MsdPlugin(), "DYNHET_MSD", m, cases);

    cases.clear();
    s4_t t;
    t = s.copy();
    t.n_shells[0] = -1;
    cases.add(new Object[] {"s4: a negative n_shells", t, true});
    t = s.copy();
    t.n_shells = new int[s.n_grids];
    Arrays.fill(t.n_shells, Integer.MAX_VALUE);
    cases.add(new Object[] {"s4: n_shells of 2^31-1 (the sum overflows an int)", t, true});
    t = s.copy();
    t.q = Arrays.copyOf(s.q, s.n_values - 1);
    cases.add(new Object[] {"s4: q 1 short", t, true});
    t = s.copy();
    t.s4[0] = Double.NaN;
    t.q[1] = 0;
    cases.add(new Object[] {"s4: NaN and q = 0", t, false});
    runCases(new S4Plugin(), "DYNHET_S4_a0.6", s, cases);

    // Bond breaking (not in the tiny scene's log): a message made here,
    // C_B = exp(-t / 3) at the overlap's lags.
    bond_breaking_t b = new bond_breaking_t();
    b.run_id = q.run_id;
    b.a1 = 1.1;
    b.a2 = 1.5;
    b.bonds_per_particle = 2.17;
    b.n_lags = n;
    b.lag_time = Arrays.copyOf(q.lag_time, n);
    b.c_b = new double[n];
    b.c_b_err = new double[n];
    for (int j = 0; j < n; ++j) b.c_b[j] = Math.exp(-b.lag_time[j] / 3);
    b.tau_b = 3;
    b.tau_b_err = 0.1;
    b.subbox_particles = new double[0];
    b.subbox_per_side = new int[0];
    b.chi_b = b.chi_b_err = b.chi_b_peak = b.tau_chi_b = b.chi_b_peak_err = b.tau_chi_b_err = new double[0];
    cases.clear();
    bond_breaking_t u = b.copy();
    u.c_b = Arrays.copyOf(b.c_b, n - 1);
    cases.add(new Object[] {"bond breaking: c_b 1 short", u, true});
    u = b.copy();
    u.n_lags = n + 1;
    cases.add(new Object[] {"bond breaking: n_lags 1 more than its arrays", u, true});
    u = b.copy();
    u.c_b[0] = Double.NaN;
    u.lag_time[1] = -1;
    cases.add(new Object[] {"bond breaking: NaN and a negative lag", u, false});
    runCases(new BondBreakingPlugin(), "DYNHET_BOND_BREAKING", b, cases);
  }

  /** Each case, then the good message: rejected ones counted and the curves kept; then the good one drawn. */
  static void runCases(SpyPlugin plugin, String channel, Object good, List<Object[]> cases) throws Exception {
    ChannelData cd = new ChannelData();
    CurveView v = edt(() -> open(plugin, cd, channel));
    for (Object[] k : cases) {
      Object bad = k[1];
      boolean reject = (Boolean)k[2];
      AtomicReference<Throwable> thrown = new AtomicReference<>();
      String why = edt(() -> {
        cd.last = good;
        v.refresh();
        int drawn = v.drawn(), rejected = v.rejected();
        cd.last = bad;
        try {
          v.refresh();
        } catch (Throwable e) {
          thrown.set(e);
        }
        if (reject) {
          if (v.rejected() != rejected + 1 || v.drawn() != drawn) return "(not counted as rejected)";
          String same = sameCurves(v, expected(good));
          return same.isEmpty() ? "" : "(the last good curves not kept: " + same + ")";
        }
        if (v.drawn() != drawn + 1 || v.rejected() != rejected) return "(not drawn)";
        return sameCurves(v, expected(bad));
      });
      String after = edt(() -> {
        cd.last = copyOf(good);
        v.refresh();
        return sameCurves(v, expected(good));
      });
      check(thrown.get() == null && why.isEmpty() && after.isEmpty(),
            k[0] + ": " +
                (reject ? "rejected and counted (" + edt(() -> v.lastRejection()) + ")"
                        : "drawn without its bad points") +
                ", nothing thrown, the next message drawn " + why + after +
                (thrown.get() == null ? "" : " threw " + thrown.get()));
    }
  }

  static Object copyOf(Object m) {
    if (m instanceof overlap_t) return ((overlap_t)m).copy();
    if (m instanceof chi4_t) return ((chi4_t)m).copy();
    if (m instanceof msd_t) return ((msd_t)m).copy();
    if (m instanceof bond_breaking_t) return ((bond_breaking_t)m).copy();
    return ((s4_t)m).copy();
  }
}
