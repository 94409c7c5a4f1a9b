package dynhet.spycheck;

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
import info.monitorenter.gui.chart.ITrace2D;
import info.monitorenter.gui.chart.ITracePoint2D;
import java.awt.Color;
import java.awt.Component;
import java.awt.Container;
import java.awt.Rectangle;
import java.awt.Robot;
import java.awt.Toolkit;
import java.awt.Window;
import java.awt.event.MouseEvent;
import java.awt.image.BufferedImage;
import java.io.File;
import java.io.IOException;
import java.lang.reflect.InvocationTargetException;
import java.util.ArrayList;
import java.util.Arrays;
import java.util.Collections;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.concurrent.Callable;
import java.util.concurrent.atomic.AtomicReference;
import javax.imageio.ImageIO;
import javax.swing.JDesktopPane;
import javax.swing.JFrame;
import javax.swing.JInternalFrame;
import javax.swing.JTable;
import javax.swing.SwingUtilities;
import lcm.logging.Log;
import lcm.spy.ChannelData;
import lcm.spy.Spy;
import lcm.spy.SpyPlugin;

/**
 * The Java half of tests/spy_plugins.sh, on a virtual display. Usage:
 * SpyPluginCheck URL LOG DONE_FILE OUT_DIR, with spy.sh's classpath.
 *
 * 1. Live: starts lcm-spy (lcm.spy.Spy.main, Debian's lcm.jar) on URL,
 *    prints "ready", and as the run's channels appear opens a curve view of
 *    DYNHET_OVERLAP_a0.6, DYNHET_CHI4_a0.6, DYNHET_MSD and DYNHET_S4_a0.6 the
 *    way a user does (a double click on the channel's row: lcm-spy picks the
 *    plugin and opens its window). A screenshot mid-run, and once DONE_FILE
 *    exists (the run has ended) another; then every view must draw exactly
 *    the curves of the last (final) message of its channel in LOG, the run's
 *    lcm-logger log, and the Q(t) view's pixels must show its curve.
 * 2. Every message: each result channel of LOG fed message by message to a
 *    fresh view (opened as lcm-spy opens one, fed as lcm-spy feeds it:
 *    ChannelData.last); after each, the view's jchart2d traces must hold
 *    exactly the message's points.
 * 3. Hostile messages: lengths that disagree with their counts, missing and
 *    empty arrays, NaN, infinities, values <= 0 on log axes, huge counts,
 *    an object of another type: each is rejected and counted (or its bad
 *    points left out), nothing is thrown, and the next good message draws.
 * The expected points are computed here from the message's fields: a point
 * (x, y) is drawn iff both are finite and, on a log axis, positive.
 */
public final class SpyPluginCheck {
  static final String[] LIVE = {"DYNHET_OVERLAP_a0.6", "DYNHET_CHI4_a0.6", "DYNHET_MSD", "DYNHET_S4_a0.6"};
  // Screen 1920 x 1080: lcm-spy top left, the views around it.
  static final Rectangle SPY = new Rectangle(0, 0, 660, 540);
  static final Rectangle[] PLACES = {new Rectangle(660, 0, 630, 540), new Rectangle(1290, 0, 630, 540),
                                     new Rectangle(660, 540, 630, 540), new Rectangle(1290, 540, 630, 540)};
  static final Color Q_COLOR = new Color(0x1f77b4); // CurveView's first colour

  static int failures = 0;
  static final List<String> uncaught = Collections.synchronizedList(new ArrayList<>());

  static void check(boolean ok, String what) {
    System.out.println((ok ? "ok   " : "FAIL ") + what);
    if (!ok) ++failures;
  }

  public static void main(String[] args) throws Exception {
    if (args.length != 4) {
      System.err.println("usage: SpyPluginCheck URL LOG DONE_FILE OUT_DIR");
      System.exit(2);
    }
    Thread.setDefaultUncaughtExceptionHandler((t, e) -> {
      uncaught.add(t.getName() + ": " + e);
      e.printStackTrace();
    });
    String limit = System.getenv("DYNHET_SPYCHECK_WATCHDOG_MS"); // to try the watchdog
    watchdog(limit == null ? 150_000 : Long.parseLong(limit));
    JFrame.setDefaultLookAndFeelDecorated(true); // title bars on a display without a window manager
    File out = new File(args[3]);
    live(args[0], new File(args[1]), new File(args[2]), out);
    Map<String, List<Object>> log = readLog(new File(args[1]));
    everyMessage(log);
    hostile(log);
    check(uncaught.isEmpty(), "nothing was thrown into Swing's or lcm-spy's threads " + uncaught);
    System.out.println(failures == 0 ? "spy plugin check: passed"
                                     : "spy plugin check: " + failures + " failed");
    System.exit(failures == 0 ? 0 : 1);
  }

  /**
   * A checker that hangs says where: after LIMIT ms every thread's stack
   * (and the threads that deadlock, if any) goes to stderr and the checker
   * exits 3, before ctest's timeout kills it silently.
   */
  static void watchdog(long limit) {
    Thread w = new Thread(() -> {
      try {
        Thread.sleep(limit);
      } catch (InterruptedException e) {
        return;
      }
      java.lang.management.ThreadMXBean mx = java.lang.management.ManagementFactory.getThreadMXBean();
      long[] dead = mx.findDeadlockedThreads();
      System.out.println("FAIL the checker is stuck after " + limit / 1000 + " s" +
                         (dead == null ? "" : " (" + dead.length + " threads deadlocked)") +
                         "; every thread's stack is in check.err");
      System.out.flush();
      for (java.lang.management.ThreadInfo t : mx.dumpAllThreads(true, true)) System.err.print(t);
      for (Map.Entry<Thread, StackTraceElement[]> e : Thread.getAllStackTraces().entrySet()) {
        System.err.println("thread " + e.getKey().getName());
        for (StackTraceElement s : e.getValue()) System.err.println("    at " + s);
      }
      System.err.flush();
      Runtime.getRuntime().halt(3);
    }, "watchdog");
    w.setDaemon(true);
    w.start();
  }

  // 1. Live, inside lcm-spy.

  static void live(String url, File logFile, File done, File out) throws Exception {
    Spy.main(new String[] {"--lcm-url=" + url});
    JTable table = edt(() -> spyTable());
    check(table != null, "lcm-spy's window and channel table are up");
    if (table == null) return;
    edt(() -> {
      SwingUtilities.getWindowAncestor(table).setBounds(SPY);
      table.getColumnModel().getColumn(0).setPreferredWidth(250); // whole channel names
      return null;
    });
    System.out.println("ready");
    System.out.flush();
    Map<String, CurveView> views = new LinkedHashMap<>();
    boolean shotLive = false;
    long deadline = System.currentTimeMillis() + 180_000;
    while (!(done.exists() && views.size() == LIVE.length)) {
      if (System.currentTimeMillis() > deadline) break;
      for (int i = 0; i < LIVE.length; ++i) {
        String ch = LIVE[i];
        if (views.containsKey(ch)) continue;
        final int place = i;
        CurveView v = edt(() -> {
          if (!doubleClick(table, ch)) return null;
          CurveView view = viewOf(ch);
          if (view != null) SwingUtilities.getWindowAncestor(view).setBounds(PLACES[place]);
          return view;
        });
        if (v != null) views.put(ch, v);
      }
      CurveView q = views.get(LIVE[0]);
      if (!shotLive && q != null && !done.exists()) {
        int drawn = edt(() -> q.drawn());
        if (drawn >= 3) {
          BufferedImage live = screenshot(new File(out, "spy_live.png"), null);
          Rectangle both = SPY.union(PLACES[0]); // lcm-spy and the Q(t) view
          ImageIO.write(live.getSubimage(both.x, both.y, both.width, both.height), "png",
                        new File(out, "spy_live_q.png"));
          shotLive = true;
          System.out.println("live screenshot after " + drawn + " Q(t) messages drawn");
        }
      }
      Thread.sleep(50);
    }
    check(views.size() == LIVE.length, "lcm-spy opened a curve view (plugin) for each of " +
                                           Arrays.toString(LIVE) +
                                           " on a double click (opened: " + views.keySet() +
                                           (views.size() == LIVE.length ? "" : "; lcm-spy's rows: " + edt(() -> rows(table))) +
                                           ")");
    check(done.exists(), "the run ended within 180 s");
    Thread.sleep(3 * CurveView.REFRESH_MS + 500); // the views' last look at lcm-spy's messages
    Map<String, List<Object>> log = readLog(logFile);
    for (Map.Entry<String, CurveView> e : views.entrySet()) {
      List<Object> messages = log.getOrDefault(e.getKey(), Collections.emptyList());
      Object last = messages.isEmpty() ? null : messages.get(messages.size() - 1);
      check(last != null && isFinal(last), e.getKey() + ": the log holds the run's final message");
      if (last == null) continue;
      CurveView v = e.getValue();
      String why = edt(() -> sameCurves(v, expected(last)));
      check(why.isEmpty(), e.getKey() + ": the live view draws exactly the final message's curves, " +
                               edt(() -> v.drawn()) + " messages drawn as they came " + why);
    }
    CurveView q = views.get(LIVE[0]);
    if (q != null) {
      int drawn = edt(() -> q.drawn());
      check(drawn >= 2 && shotLive,
            "the Q(t) view updated as messages arrived (" + drawn + " messages drawn, a screenshot mid-run)");
    }
    BufferedImage screen = screenshot(new File(out, "spy_final.png"), null);
    for (Map.Entry<String, CurveView> e : views.entrySet()) {
      Rectangle r = edt(() -> SwingUtilities.getWindowAncestor(e.getValue()).getBounds());
      File f = new File(out, "view_" + e.getKey() + ".png");
      ImageIO.write(screen.getSubimage(r.x, r.y, r.width, r.height), "png", f);
    }
    if (q != null) {
      // Pixels of the Q(t) curve's colour inside the chart, not just the legend.
      Rectangle chart = edt(() -> {
        Rectangle b = q.chart().getBounds();
        java.awt.Point p = q.chart().getLocationOnScreen();
        return new Rectangle(p.x, p.y, b.width, b.height);
      });
      int n = 0;
      for (int y = chart.y; y < chart.y + chart.height; ++y)
        for (int x = chart.x; x < chart.x + chart.width; ++x)
          if (close(new Color(screen.getRGB(x, y)), Q_COLOR)) ++n;
      check(n > 300, "the screen shows the Q(t) curve: " + n + " pixels of its colour in the chart");
    }
  }

  static boolean close(Color a, Color b) {
    return Math.abs(a.getRed() - b.getRed()) < 30 && Math.abs(a.getGreen() - b.getGreen()) < 30 &&
        Math.abs(a.getBlue() - b.getBlue()) < 30;
  }

  static JTable spyTable() {
    for (Window w : Window.getWindows())
      if (w instanceof JFrame && "LCM Spy".equals(((JFrame)w).getTitle())) return find(w, JTable.class);
    return null;
  }

  static <T> T find(Component c, Class<T> cls) {
    if (cls.isInstance(c)) return cls.cast(c);
    if (c instanceof Container)
      for (Component child : ((Container)c).getComponents()) {
        T t = find(child, cls);
        if (t != null) return t;
      }
    return null;
  }

  /** A user's double click on the channel's row; false while the channel has no row. */
  static boolean doubleClick(JTable table, String channel) {
    for (int row = 0; row < table.getRowCount(); ++row)
      if (channel.equals(table.getValueAt(row, 0))) {
        Rectangle cell = table.getCellRect(row, 0, true);
        table.dispatchEvent(new MouseEvent(table, MouseEvent.MOUSE_CLICKED, System.currentTimeMillis(), 0,
                                           cell.x + cell.width / 2, cell.y + cell.height / 2, 2, false,
                                           MouseEvent.BUTTON1));
        return true;
      }
    return false;
  }

  static List<Object> rows(JTable table) {
    List<Object> r = new ArrayList<>();
    for (int row = 0; row < table.getRowCount(); ++row) r.add(table.getValueAt(row, 0));
    return r;
  }

  static CurveView viewOf(String channel) {
    for (Window w : Window.getWindows()) {
      if (!w.isVisible()) continue;
      JDesktopPane d = find(w, JDesktopPane.class);
      if (d == null) continue;
      for (JInternalFrame f : d.getAllFrames())
        if (f instanceof CurveView && channel.equals(f.getTitle())) return (CurveView)f;
    }
    return null;
  }

  static BufferedImage screenshot(File file, Rectangle area) throws Exception {
    Toolkit.getDefaultToolkit().sync();
    Thread.sleep(400);
    Rectangle r = area != null ? area : new Rectangle(Toolkit.getDefaultToolkit().getScreenSize());
    BufferedImage img = new Robot().createScreenCapture(r);
    ImageIO.write(img, "png", file);
    return img;
  }

  // 2. Every message of the log, one by one.

  static void everyMessage(Map<String, List<Object>> log) throws Exception {
    int channels = 0, messages = 0;
    for (Map.Entry<String, List<Object>> e : log.entrySet()) {
      List<Object> list = e.getValue();
      SpyPlugin plugin = pluginFor(list.get(0));
      if (plugin == null) continue;
      ChannelData cd = new ChannelData();
      CurveView v = edt(() -> open(plugin, cd, e.getKey()));
      String why = "";
      for (Object m : list) {
        why = edt(() -> {
          cd.last = m; // what lcm-spy does with each message it decodes
          v.refresh();
          return sameCurves(v, expected(m));
        });
        if (!why.isEmpty()) break;
        ++messages;
      }
      int drawn = edt(() -> v.drawn()), rejected = edt(() -> v.rejected());
      check(why.isEmpty() && drawn == list.size() && rejected == 0,
            e.getKey() + ": after each of its " + list.size() +
                " messages the view's traces hold exactly its points " + why);
      ++channels;
      edt(() -> {
        SwingUtilities.getWindowAncestor(v).dispose();
        return null;
      });
    }
    check(channels >= 7, channels + " result channels of the log checked, " + messages + " messages");
  }

  static SpyPlugin pluginFor(Object m) {
    if (m instanceof overlap_t) return new OverlapPlugin();
    if (m instanceof chi4_t) return new Chi4Plugin();
    if (m instanceof msd_t) return new MsdPlugin();
    if (m instanceof s4_t) return new S4Plugin();
    if (m instanceof bond_breaking_t) return new BondBreakingPlugin();
    return null;
  }

  /** A view opened as lcm-spy's PluginStarter opens one: a frame, a desktop, the plugin's action. */
  static CurveView open(SpyPlugin plugin, ChannelData cd, String channel) {
    cd.name = channel;
    JFrame frame = new JFrame(channel);
    JDesktopPane desktop = new JDesktopPane();
    frame.add(desktop);
    frame.setSize(500, 400);
    frame.setVisible(true);
    plugin.getAction(desktop, cd).actionPerformed(null);
    return (CurveView)desktop.getAllFrames()[0];
  }

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

  static List<Curve> expected(Object message) {
    List<Curve> out = new ArrayList<>();
    if (message instanceof overlap_t) {
      overlap_t m = (overlap_t)message;
      Curve q = new Curve("Q(t)");
      double lo = Double.POSITIVE_INFINITY, hi = 0;
      for (int j = 0; j < m.n_lags; ++j) {
        add(q, m.lag_time[j], m.q[j], true, false);
        if (Double.isFinite(m.lag_time[j]) && m.lag_time[j] > 0) {
          lo = Math.min(lo, m.lag_time[j]);
          hi = Math.max(hi, m.lag_time[j]);
        }
      }
      out.add(q);
      if (hi > 0) {
        Curve e = new Curve("1/e");
        e.points.add(new double[] {lo, Math.exp(-1)});
        e.points.add(new double[] {hi, Math.exp(-1)});
        out.add(e);
      }
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
      Curve cb = new Curve("C_B(t)");
      double lo = Double.POSITIVE_INFINITY, hi = 0;
      for (int j = 0; j < m.n_lags; ++j) {
        add(cb, m.lag_time[j], m.c_b[j], true, false);
        if (Double.isFinite(m.lag_time[j]) && m.lag_time[j] > 0) {
          lo = Math.min(lo, m.lag_time[j]);
          hi = Math.max(hi, m.lag_time[j]);
        }
      }
      out.add(cb);
      if (hi > 0) {
        Curve e = new Curve("1/e");
        e.points.add(new double[] {lo, Math.exp(-1)});
        e.points.add(new double[] {hi, Math.exp(-1)});
        out.add(e);
      }
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

  // The log: every result message of the four types, decoded, by channel.

  static Map<String, List<Object>> readLog(File file) throws IOException {
    Map<String, List<Object>> out = new LinkedHashMap<>();
    Log log = new Log(file.getPath(), "r");
    try {
      for (;;) {
        Log.Event e = log.readNext();
        Object m = decode(e.data);
        if (m != null) out.computeIfAbsent(e.channel, k -> new ArrayList<>()).add(m);
      }
    } catch (java.io.EOFException end) {
      // the end of the log
    } finally {
      log.close();
    }
    return out;
  }

  static Object decode(byte[] data) throws IOException {
    if (data.length < 8) return null;
    long fingerprint = java.nio.ByteBuffer.wrap(data, 0, 8).getLong();
    if (fingerprint == overlap_t.LCM_FINGERPRINT) return new overlap_t(data);
    if (fingerprint == chi4_t.LCM_FINGERPRINT) return new chi4_t(data);
    if (fingerprint == msd_t.LCM_FINGERPRINT) return new msd_t(data);
    if (fingerprint == s4_t.LCM_FINGERPRINT) return new s4_t(data);
    return null;
  }

  static Object last(Map<String, List<Object>> log, String channel) {
    List<Object> l = log.get(channel);
    return l == null || l.isEmpty() ? null : l.get(l.size() - 1);
  }

  static <T> T edt(Callable<T> f) throws Exception {
    AtomicReference<T> result = new AtomicReference<>();
    AtomicReference<Exception> error = new AtomicReference<>();
    try {
      SwingUtilities.invokeAndWait(() -> {
        try {
          result.set(f.call());
        } catch (Exception e) {
          error.set(e);
        }
      });
    } catch (InvocationTargetException e) {
      throw new RuntimeException(e.getCause());
    }
    if (error.get() != null) throw error.get();
    return result.get();
  }
}
