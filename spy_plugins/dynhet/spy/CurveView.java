package dynhet.spy;

import info.monitorenter.gui.chart.Chart2D;
import info.monitorenter.gui.chart.IAxis;
import info.monitorenter.gui.chart.ITrace2D;
import info.monitorenter.gui.chart.axis.AAxis;
import info.monitorenter.gui.chart.axis.AxisLinear;
import info.monitorenter.gui.chart.controls.LayoutFactory;
import info.monitorenter.gui.chart.traces.Trace2DSimple;
import info.monitorenter.gui.chart.traces.painters.TracePainterDisc;
import info.monitorenter.gui.chart.views.ChartPanel;
import java.awt.BasicStroke;
import java.awt.BorderLayout;
import java.awt.Color;
import java.awt.Window;
import java.awt.event.ActionEvent;
import java.awt.event.ComponentAdapter;
import java.awt.event.ComponentEvent;
import java.awt.event.HierarchyEvent;
import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import javax.swing.AbstractAction;
import javax.swing.Action;
import javax.swing.BorderFactory;
import javax.swing.JDesktopPane;
import javax.swing.JFrame;
import javax.swing.JInternalFrame;
import javax.swing.JLabel;
import javax.swing.SwingUtilities;
import javax.swing.Timer;
import javax.swing.event.InternalFrameAdapter;
import javax.swing.event.InternalFrameEvent;
import javax.swing.plaf.basic.BasicInternalFrameUI;
import lcm.spy.ChannelData;

/**
 * A live chart of one channel's curves inside lcm-spy. lcm-spy decodes every
 * message it receives and keeps the latest in {@link ChannelData#last} (what
 * its own structure viewer shows); the view looks at it five times a second
 * on Swing's thread and redraws when it is a new message. So it uses
 * lcm-spy's own bus and decoding (no second connection, whatever the URL),
 * and a view opened after a run shows that run's last result at once. (After
 * lcm-spy's Clear button forgets the channel, an open view stops updating:
 * open it again.) Every message is untrusted: one the curves cannot be made
 * of is counted and named in the status line, never thrown into lcm-spy.
 */
public final class CurveView extends JInternalFrame {
  private static final long serialVersionUID = 1L;

  /** The curves of one message; throws for a message that cannot be drawn. */
  interface Extractor {
    Curves curves(Object message) throws Curves.BadMessage;
  }

  public static final int REFRESH_MS = 200;
  private static final Color[] PALETTE = {new Color(0x1f77b4), new Color(0xd62728), new Color(0x2ca02c),
                                          new Color(0xff7f0e), new Color(0x9467bd), new Color(0x17becf),
                                          new Color(0x8c564b), new Color(0xe377c2)};

  /**
   * The action lcm-spy puts in its menu. lcm-spy asks for it once with no
   * desktop and no channel, only for its name.
   */
  static Action action(String name, JDesktopPane desktop, ChannelData channel, Extractor extractor) {
    return new AbstractAction(name) {
      private static final long serialVersionUID = 1L;

      public void actionPerformed(ActionEvent e) {
        if (desktop == null || channel == null) return;
        try {
          open(desktop, channel, name, extractor);
        } catch (RuntimeException ex) {
          System.err.println(name + ": cannot open a view of " + channel.name + ": " + ex);
        }
      }
    };
  }

  private static void open(JDesktopPane desktop, ChannelData channel, String name, Extractor extractor) {
    CurveView view = new CurveView(channel, extractor);
    desktop.add(view);
    // lcm-spy makes the window 500 x 400: too small for a chart with a legend.
    Window window = SwingUtilities.getWindowAncestor(desktop);
    if (window != null) {
      window.setSize(Math.max(window.getWidth(), 780), Math.max(window.getHeight(), 560));
      if (window instanceof JFrame) ((JFrame)window).setTitle(channel.name + " \u2014 " + name);
      window.validate();
    }
    // The view fills the window (it has its own title).
    desktop.addComponentListener(new ComponentAdapter() {
      @Override
      public void componentResized(ComponentEvent e) {
        view.setBounds(0, 0, desktop.getWidth(), desktop.getHeight());
      }
    });
    view.setBounds(0, 0, Math.max(desktop.getWidth(), 1), Math.max(desktop.getHeight(), 1));
    view.setVisible(true);
    view.refresh();
  }

  private final ChannelData channel;
  private final Extractor extractor;
  private final Chart2D chart = new Chart2D();
  private final JLabel summary = new JLabel(" ");
  private final JLabel status = new JLabel(" ");
  private final List<ITrace2D> traces = new ArrayList<>();
  private final Timer timer;
  private boolean axesSet = false;
  private Object shown = null;
  private int drawn = 0, rejected = 0, leftOut = 0;
  private String lastRejection = "";

  static {
    // jchart2d's menus on the chart (right click): keep saving, printing,
    // grids and each curve's colour, stroke and visibility; leave out what
    // would break the view: jchart2d's own log axis (it throws for values
    // below 1), renaming or removing a curve (the view keeps its curves by
    // name). lcm-spy has no jchart2d menus of its own.
    LayoutFactory f = LayoutFactory.getInstance();
    f.setShowAxisXTypeMenu(false);
    f.setShowAxisYTypeMenu(false);
    f.setShowRemoveTraceMenu(false);
    f.setShowTraceNameMenu(false);
    f.setShowAnnotationMenu(false);
    f.setShowErrorBarWizardMenu(false);
    f.setShowPhysicalUnitsMenu(false);
  }

  CurveView(ChannelData channel, Extractor extractor) {
    super(channel.name, true, false, true, false);
    this.channel = channel;
    this.extractor = extractor;
    if (getUI() instanceof BasicInternalFrameUI) ((BasicInternalFrameUI)getUI()).setNorthPane(null);
    setBorder(BorderFactory.createEmptyBorder());
    summary.setBorder(BorderFactory.createEmptyBorder(4, 8, 4, 8));
    status.setBorder(BorderFactory.createEmptyBorder(2, 8, 4, 8));
    chart.setUseAntialiasing(true);
    chart.setBackground(Color.WHITE);
    setLayout(new BorderLayout());
    add(summary, BorderLayout.NORTH);
    add(new ChartPanel(chart), BorderLayout.CENTER);
    add(status, BorderLayout.SOUTH);
    timer = new Timer(REFRESH_MS, e -> refresh());
    // Only while the window shows (lcm-spy hides a closed plugin window).
    addHierarchyListener(e -> {
      if ((e.getChangeFlags() & HierarchyEvent.SHOWING_CHANGED) == 0) return;
      if (isShowing())
        timer.start();
      else
        timer.stop();
    });
    addInternalFrameListener(new InternalFrameAdapter() {
      @Override
      public void internalFrameClosed(InternalFrameEvent e) {
        timer.stop();
      }
    });
  }

  /** Draws lcm-spy's latest message of the channel if it is a new one (Swing's thread). */
  public void refresh() {
    Object message = channel.last; // set by lcm-spy's receive thread
    if (message == null || message == shown) return;
    shown = message;
    try {
      draw(extractor.curves(message));
      ++drawn;
    } catch (Curves.BadMessage e) {
      ++rejected;
      lastRejection = e.getMessage();
    } catch (Throwable e) { // never into lcm-spy
      ++rejected;
      lastRejection = e.toString();
    }
    showStatus();
  }

  public Chart2D chart() { return chart; }

  /** The chart's traces, one per curve, in the order of the message's curves. */
  public List<ITrace2D> traces() { return Collections.unmodifiableList(traces); }

  /** Messages drawn and messages rejected since the view opened. */
  public int drawn() { return drawn; }

  public int rejected() { return rejected; }

  public String lastRejection() { return lastRejection; }

  /** Points of the last message left out: not finite, or not positive on a log axis. */
  public int leftOut() { return leftOut; }

  /** Whether the view draws the point (x, y) on the axes of `c`. */
  static boolean drawable(Curves c, double x, double y) {
    return Double.isFinite(x) && Double.isFinite(y) && (!c.logX || x > 0) && (!c.logY || y > 0);
  }

  private void draw(Curves c) {
    if (!axesSet) {
      setAxes(c);
      axesSet = true;
    }
    List<Curves.Series> series = c.series();
    boolean same = series.size() == traces.size();
    for (int i = 0; same && i < series.size(); ++i) same = series.get(i).name.equals(traces.get(i).getName());
    if (!same) {
      chart.removeAllTraces();
      traces.clear();
      for (int i = 0; i < series.size(); ++i) traces.add(newTrace(series.get(i).name, i));
    }
    leftOut = 0;
    for (int i = 0; i < series.size(); ++i) {
      Curves.Series s = series.get(i);
      ITrace2D t = traces.get(i);
      t.removeAllPoints();
      for (int k = 0; k < s.x.length; ++k)
        if (drawable(c, s.x[k], s.y[k]))
          t.addPoint(s.x[k], s.y[k]);
        else
          ++leftOut;
    }
    StringBuilder html = new StringBuilder("<html><b>").append(escape(c.title)).append("</b>");
    for (String line : c.summary()) html.append("<br>").append(escape(line));
    summary.setText(html.append("</html>").toString());
  }

  private ITrace2D newTrace(String name, int index) {
    ITrace2D t = new Trace2DSimple(name);
    boolean reference = name.equals("1/e");
    t.setColor(reference ? Color.GRAY : PALETTE[index % PALETTE.length]);
    t.setStroke(reference ? new BasicStroke(1f, BasicStroke.CAP_BUTT, BasicStroke.JOIN_MITER, 10f,
                                            new float[] {6f, 4f}, 0f)
                          : new BasicStroke(2f));
    chart.addTrace(t);
    if (!reference) t.addTracePainter(new TracePainterDisc(5));
    return t;
  }

  private void setAxes(Curves c) {
    chart.setAxisXBottom(axis(c.logX), 0);
    chart.setAxisYLeft(axis(c.logY), 0);
    chart.getAxisX().setAxisTitle(new IAxis.AxisTitle(c.xLabel + (c.logX ? " (log)" : "")));
    chart.getAxisY().setAxisTitle(new IAxis.AxisTitle(c.yLabel + (c.logY ? " (log)" : "")));
    chart.getAxisX().setPaintGrid(true);
    chart.getAxisY().setPaintGrid(true);
  }

  private static AAxis<?> axis(boolean log) { return log ? new Log10Axis() : new AxisLinear<>(); }

  private void showStatus() {
    String s = drawn + " messages drawn";
    if (leftOut > 0) s += " \u00b7 " + leftOut + " points not drawn (NaN, or \u2264 0 on a log axis)";
    if (rejected > 0) s += " \u00b7 " + rejected + " rejected, the last: " + lastRejection;
    status.setText(s);
  }

  private static String escape(String s) {
    return s.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;");
  }
}
