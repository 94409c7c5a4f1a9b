package dynhet.spycheck;

import dynhet.bond_breaking_t;
import dynhet.chi4_t;
import dynhet.msd_t;
import dynhet.overlap_t;
import dynhet.s4_t;
import dynhet.spy.CurveView;
import info.monitorenter.gui.chart.ITrace2D;
import info.monitorenter.gui.chart.ITracePoint2D;
import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;

/** What a curve view must draw for a result message, computed from its fields, and the comparison (SpyPluginCheck). */
final class ExpectedCurves {
  private ExpectedCurves() {}

  // What a view must draw: computed from the message's fields.

  static final class Curve {
    final String name; // the name the trace must have, or a prefix of it ending in '*'
    final List<double[]> points = new ArrayList<>();

    Curve(String name) { this.name = name; }
  }

  static void add(Curve c, double x, double y, boolean logX, boolean logY) {
    if (Double.isFinite(x) && Double.isFinite(y) && (!logX || x > 0) && (!logY || y > 0))
      c.points.add(new double[] {x, y});
  }

  static String gridName(int perSide) { return perSide == 1 ? "whole box" : "N_r = *"; }

  /** The 1/e line the overlap and bond-breaking views draw across their lags. */
  static Curve oneOverE(double lo, double hi) {
    Curve e = new Curve("1/e");
    e.points.add(new double[] {lo, Math.exp(-1)});
    e.points.add(new double[] {hi, Math.exp(-1)});
    return e;
  }

  // A decay from 1 (Q(t), C_B(t)) and the 1/e line over its lags.
  static void decay(List<Curve> out, String name, double[] t, double[] y, int n) {
    Curve c = new Curve(name);
    double lo = Double.POSITIVE_INFINITY, hi = 0;
    for (int j = 0; j < n; ++j) {
      add(c, t[j], y[j], true, false);
      if (Double.isFinite(t[j]) && t[j] > 0) {
        lo = Math.min(lo, t[j]);
        hi = Math.max(hi, t[j]);
      }
    }
    out.add(c);
    if (hi > 0) out.add(oneOverE(lo, hi));
  }

  static List<Curve> expected(Object message) {
    List<Curve> out = new ArrayList<>();
    if (message instanceof overlap_t) {
      overlap_t m = (overlap_t)message;
      decay(out, "Q(t)", m.lag_time, m.q, m.n_lags);
    } else if (message instanceof chi4_t) {
      chi4_t m = (chi4_t)message;
      for (int g = 0; g < m.n_grids; ++g) {
        Curve c = new Curve(gridName(m.subbox_per_side[g]));
        for (int j = 0; j < m.n_lags; ++j) add(c, m.lag_time[j], m.chi4[g * m.n_lags + j], true, true);
        out.add(c);
      }
    } else if (message instanceof msd_t) {
      msd_t m = (msd_t)message;
      String[] names = {"all", "small", "fastest *", "slowest *", "fastest *", "slowest *"};
      double[][] ys = {m.msd_all,      m.msd_small,      m.msd_fast_all,
                       m.msd_slow_all, m.msd_fast_small, m.msd_slow_small};
      for (int s = 0; s < names.length; ++s) {
        Curve c = new Curve(names[s]);
        for (int j = 0; j < m.n_lags; ++j) add(c, m.lag_time[j], ys[s][j], true, true);
        out.add(c);
      }
    } else if (message instanceof bond_breaking_t) {
      bond_breaking_t m = (bond_breaking_t)message;
      decay(out, "C_B(t)", m.lag_time, m.c_b, m.n_lags);
    } else if (message instanceof s4_t) {
      s4_t m = (s4_t)message;
      int v = 0;
      for (int g = 0; g < m.n_grids; ++g) {
        Curve c = new Curve(gridName(m.subbox_per_side[g]));
        for (int k = 0; k < m.n_shells[g]; ++k, ++v) add(c, m.q[v], m.s4[v], true, true);
        out.add(c);
      }
    }
    return out;
  }

  /** "" if the view's traces are the curves, point for point and bit for bit; else what differs. */
  static String sameCurves(CurveView v, List<Curve> want) {
    List<ITrace2D> traces = v.traces();
    if (traces.size() != want.size()) return "(" + traces.size() + " traces for " + want.size() + " curves)";
    for (int i = 0; i < want.size(); ++i) {
      ITrace2D t = traces.get(i);
      Curve c = want.get(i);
      if (!v.chart().getTraces().contains(t)) return "(trace " + t.getName() + " is not in the chart)";
      boolean nameOk = c.name.endsWith("*") ? t.getName().startsWith(c.name.substring(0, c.name.length() - 1))
                                            : t.getName().equals(c.name);
      if (!nameOk) return "(trace " + i + " is named " + t.getName() + ", not " + c.name + ")";
      List<double[]> got = new ArrayList<>();
      for (java.util.Iterator<ITracePoint2D> it = t.iterator(); it.hasNext();) {
        ITracePoint2D p = it.next();
        got.add(new double[] {p.getX(), p.getY()});
      }
      if (got.size() != c.points.size())
        return "(" + t.getName() + ": " + got.size() + " points for " + c.points.size() + ")";
      for (int k = 0; k < got.size(); ++k)
        if (Double.compare(got.get(k)[0], c.points.get(k)[0]) != 0 ||
            Double.compare(got.get(k)[1], c.points.get(k)[1]) != 0)
          return "(" + t.getName() + " point " + k + ": " + Arrays.toString(got.get(k)) + " for " +
              Arrays.toString(c.points.get(k)) + ")";
    }
    return "";
  }

  static boolean isFinal(Object m) {
    if (m instanceof overlap_t) return ((overlap_t)m).is_final;
    if (m instanceof chi4_t) return ((chi4_t)m).is_final;
    if (m instanceof msd_t) return ((msd_t)m).is_final;
    if (m instanceof s4_t) return ((s4_t)m).is_final;
    return false;
  }
}
