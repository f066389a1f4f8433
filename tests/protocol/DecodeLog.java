// What lcm-spy does with covtrack's jar, without a window: reads an LCM log and decodes
// every pose and heartbeat event with the jar's classes (decoding checks the type's
// fingerprint, as lcm-spy's matching does). Exits 1 when an event does not decode, when
// its device or sensor disagrees with its channel, or when the log has no such events.
// Usage: java -cp lcm.jar:covtrack_lcmtypes.jar:. DecodeLog LOG
import covtrack.device_status_t;
import covtrack.pose_cov_t;
import java.io.EOFException;
import lcm.logging.Log;

public class DecodeLog {
  public static void main(String[] args) throws Exception {
    Log log = new Log(args[0], "r");
    int poses = 0, statuses = 0, failures = 0;
    String first = null;
    while (true) {
      Log.Event event;
      try {
        event = log.readNext();
      } catch (EOFException end) {
        break;
      }
      try {
        if (event.channel.startsWith("covtrack/pose/")) {
          pose_cov_t p = new pose_cov_t(event.data);
          if (!event.channel.equals("covtrack/pose/" + p.device + "/" + p.sensor)) {
            System.out.println("channel " + event.channel + " carries " + p.device + "/" + p.sensor);
            ++failures;
          }
          if (first == null)
            first = String.format("%s/%s in %s: [%.4f %.4f %.4f], status %d", p.device, p.sensor, p.parent_frame,
                                  p.position_m[0], p.position_m[1], p.position_m[2], p.status);
          ++poses;
        } else if (event.channel.startsWith("covtrack/status/")) {
          device_status_t s = new device_status_t(event.data);
          if (!event.channel.equals("covtrack/status/" + s.device)) {
            System.out.println("channel " + event.channel + " carries device " + s.device);
            ++failures;
          }
          ++statuses;
        }
      } catch (java.io.IOException e) {
        System.out.println(event.channel + ": does not decode: " + e.getMessage());
        ++failures;
      }
    }
    System.out.println("decoded " + poses + " pose_cov_t and " + statuses + " device_status_t; first: " + first);
    System.exit(failures == 0 && poses > 0 && statuses > 0 ? 0 : 1);
  }
}
