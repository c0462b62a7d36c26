#pragma once
// DDS discovery for the tests of the ROS 2 base.

#include <cstdlib>

/// DDS discovery over loopback only, by unicast: works on a machine without multicast (CI containers).
/// Leaves a CYCLONEDDS_URI the caller already set.
inline void use_loopback_dds() {
  ::setenv("CYCLONEDDS_URI",
           "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces>"
           "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
           "<MaxAutoParticipantIndex>60</MaxAutoParticipantIndex><Peers><Peer Address=\"127.0.0.1\"/></Peers></Discovery>"
           "</Domain></CycloneDDS>",
           0);
}
