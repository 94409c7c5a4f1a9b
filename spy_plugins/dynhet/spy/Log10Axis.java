package dynhet.spy;

import info.monitorenter.gui.chart.IAxis;
import info.monitorenter.gui.chart.LabeledValue;
import info.monitorenter.gui.chart.axis.AAxisTransformation;
import info.monitorenter.gui.chart.axis.scalepolicy.AxisScalePolicyTransformation;
import info.monitorenter.gui.chart.labelformatters.LabelFormatterSimple;
import info.monitorenter.util.Range;
import java.awt.Graphics;
import java.util.ArrayList;
import java.util.List;

/**
 * A log10 axis for values of any size, with ticks at 1, 2 and 5 times the
 * powers of ten in range. jchart2d 3.2.2's AxisLog10 throws (while
 * painting) for values below 1, and its ticks start at 1: lags, Q and S4
 * are mostly below 1. The view gives it only positive values; the range's
 * own bounds, which can be 0 while the chart is empty, map to 0 (as if 1),
 * as AxisLog10 does for an empty chart.
 */
final class Log10Axis extends AAxisTransformation<AxisScalePolicyTransformation> {
  private static final long serialVersionUID = 1L;

  Log10Axis() { super(new LabelFormatterSimple(), new Ticks()); }

  @Override
  public double transform(double in) {
    return in > 0 && Double.isFinite(in) ? Math.log10(in) : 0;
  }

  @Override
  public double untransform(double in) {
    return Math.pow(10, in);
  }

  /** Ticks at 1 x 10^k (labelled), and at 2 and 5 x 10^k over less than two decades. */
  static final class Ticks extends AxisScalePolicyTransformation {
    @Override
    public List<LabeledValue> getScaleValues(Graphics g, IAxis<?> axis) {
      List<LabeledValue> out = new ArrayList<>();
      if (!(axis instanceof AAxisTransformation)) return out;
      AAxisTransformation<?> a = (AAxisTransformation<?>)axis;
      Range r = axis.getRange();
      double lo = a.transform(r.getMin()), hi = a.transform(r.getMax());
      if (!(hi - lo > 1e-9) || !Double.isFinite(hi - lo)) return out;
      double[] multiples = hi - lo < 2 ? new double[] {1, 2, 5} : new double[] {1};
      int step = (int)Math.max(1, Math.ceil((hi - lo) / 8)); // at most about 8 decades labelled
      for (long k = (long)Math.floor(lo); k <= (long)Math.ceil(hi); k += step)
        for (double m : multiples) {
          double t = k + Math.log10(m);
          if (t < lo - 1e-9 || t > hi + 1e-9) continue;
          LabeledValue v = new LabeledValue();
          v.setValue((t - lo) / (hi - lo)); // position along the axis, 0..1
          v.setLabel(Curves.num(m * Math.pow(10, k)));
          v.setMajorTick(m == 1);
          out.add(v);
        }
      return out;
    }
  }
}
