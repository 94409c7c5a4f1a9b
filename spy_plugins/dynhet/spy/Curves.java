package dynhet.spy;

import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.Locale;

/**
 * What a view draws for one message: named series of (x, y) points, the
 * axes and a summary line. Built from a decoded message, which is untrusted:
 * every length is checked against its count field and against the others
 * before an index is used (a bad message throws {@link BadMessage}, and the
 * view counts it); values are taken as they are (NaN included: the view
 * leaves out the points an axis cannot show).
 */
final class Curves {
  /** Drawing more would stall lcm-spy's window; no dynhet run sends as much. */
  static final int MAX_SERIES = 16;
  static final int MAX_POINTS = 200_000;

  /** A message the view cannot draw, and why. */
  static final class BadMessage extends Exception {
    private static final long serialVersionUID = 1L;

    BadMessage(String why) { super(why); }
  }

  /** One curve: points (x[i], y[i]). */
  static final class Series {
    final String name;
    final double[] x, y;

    Series(String name, double[] x, double[] y) {
      this.name = name;
      this.x = x;
      this.y = y;
    }
  }

  final String title, xLabel, yLabel;
  final boolean logX, logY;
  private final List<Series> series = new ArrayList<>();
  private final List<String> summary = new ArrayList<>();
  private int points = 0;

  Curves(String title, String xLabel, String yLabel, boolean logX, boolean logY) {
    this.title = title;
    this.xLabel = xLabel;
    this.yLabel = yLabel;
    this.logX = logX;
    this.logY = logY;
  }

  List<Series> series() { return Collections.unmodifiableList(series); }

  List<String> summary() { return Collections.unmodifiableList(summary); }

  /** A summary line (the view shows them above the chart). */
  Curves say(String line) {
    summary.add(line);
    return this;
  }

  /** The series `name`: x[i], y[from + i] for i in [0, n). */
  void add(String name, double[] x, double[] y, int from, int n) throws BadMessage {
    need(series.size() < MAX_SERIES, "more than " + MAX_SERIES + " curves");
    need(n >= 0 && from >= 0 && x != null && y != null && n <= x.length && (long)from + n <= y.length,
         name + ": values out of range");
    points += n;
    need(points <= MAX_POINTS, "more than " + MAX_POINTS + " points");
    double[] xs = new double[n], ys = new double[n];
    System.arraycopy(x, 0, xs, 0, n);
    System.arraycopy(y, from, ys, 0, n);
    series.add(new Series(name, xs, ys));
  }

  // Checks of an untrusted message.

  /** The line 1/e across the positive, finite lags (none without any). */
  void addOneOverE(double[] lags) throws BadMessage {
    double lo = Double.POSITIVE_INFINITY, hi = 0;
    for (double t : lags)
      if (Double.isFinite(t) && t > 0) {
        lo = Math.min(lo, t);
        hi = Math.max(hi, t);
      }
    if (hi > 0) add("1/e", new double[] {lo, hi}, new double[] {Math.exp(-1), Math.exp(-1)}, 0, 2);
  }

  /** A title's suffix for results of the cage-relative displacements (channels with _CR). */
  static String cageRelative(boolean cr) { return cr ? " (cage-relative)" : ""; }

  static void need(boolean ok, String why) throws BadMessage {
    if (!ok) throw new BadMessage(why);
  }

  /** `a` holds exactly `n` values (its count field), n >= 0. */
  static void length(double[] a, long n, String name) throws BadMessage {
    need(a != null && n >= 0 && a.length == n,
         name + ": " + (a == null ? "missing" : a.length + " values") + " for a count of " + n);
  }

  static void length(int[] a, long n, String name) throws BadMessage {
    need(a != null && n >= 0 && a.length == n,
         name + ": " + (a == null ? "missing" : a.length + " values") + " for a count of " + n);
  }

  // Numbers for the summary line.

  /** Four significant digits, no trailing zeros: 0.6, 12.5, 1.234e-05; "n/a" if not finite. */
  static String num(double v) {
    if (!Double.isFinite(v)) return "n/a";
    String s = String.format(Locale.ROOT, "%.4g", v);
    int e = s.indexOf('e');
    String mantissa = e < 0 ? s : s.substring(0, e), exponent = e < 0 ? "" : s.substring(e);
    if (mantissa.indexOf('.') >= 0) mantissa = mantissa.replaceAll("0+$", "").replaceAll("\\.$", "");
    return mantissa + exponent;
  }

  static String pm(double v, double err) {
    return Double.isFinite(err) ? num(v) + " \u00b1 " + String.format(Locale.ROOT, "%.2g", err) : num(v);
  }

  /** "run 4242 · frame 52 (t = 15.3), final". */
  static String stamp(long runId, int frame, double simTime, boolean isFinal) {
    return "run " + runId + " \u00b7 frame " + frame + " (t = " + num(simTime) + ")" +
        (isFinal ? " \u00b7 final" : "");
  }
}
