package dynhet.spycheck;

import static dynhet.spycheck.ExpectedCurves.*;
import static dynhet.spycheck.HostileCases.*;
import static dynhet.spycheck.SpyLog.*;

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
