package dynhet.spycheck;

import dynhet.chi4_t;
import dynhet.msd_t;
import dynhet.overlap_t;
import dynhet.s4_t;
import java.io.File;
import java.io.IOException;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import lcm.logging.Log;

/** A run's lcm-logger log as SpyPluginCheck reads it. */
final class SpyLog {
  private SpyLog() {}

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
}
