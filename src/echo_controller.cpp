// echo_controller: the smallest controller in the loop, for DRCSim 2.6's synchronization window
// and the bench (bench/run_bench.py's `controller` section).
//
// It answers every /atlas/atlas_state with one /atlas/atlas_command stamped with that state's
// header stamp: every joint held where the state says it is (position = the state's positions,
// velocity and effort 0), with the gains of the parameter server (atlas_controller/gains/
// <joint>/{p,i,d,i_clamp}, as config/atlas_controller.yaml loads them) and k_effort 255 (the
// PID alone). The command is computed from the state alone, so the same states give the same
// commands, bit for bit: with the window on (--period-ms) at real_time_factor:=0, two runs are
// the same run.
//
// usage: echo_controller [--transport tcp|udp|udp-then-tcp] [--period-ms N] [ROS remappings]
//   --transport: how /atlas/atlas_state is subscribed: tcp (TransportHints().tcpNoDelay(),
//     the default), udp (.unreliable() only, as the tutorial's C++ client), udp-then-tcp
//     (.unreliable().reliable().tcpNoDelay(), as DRCSim's own clients). A publisher that serves
//     no UDPROS never connects to a udp subscriber.
//   --period-ms: desired_controller_period_ms of every command (0..255, default 0: no window).

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <atlas_msgs/AtlasCommand.h>
#include <atlas_msgs/AtlasState.h>
#include <ros/ros.h>

namespace
{
// The 28 joints in AtlasState's (and AtlasCommand's) order.
const char *const kJointNames[] = {
  "back_lbz", "back_mby", "back_ubx", "neck_ay",
  "l_leg_uhz", "l_leg_mhx", "l_leg_lhy", "l_leg_kny", "l_leg_uay", "l_leg_lax",
  "r_leg_uhz", "r_leg_mhx", "r_leg_lhy", "r_leg_kny", "r_leg_uay", "r_leg_lax",
  "l_arm_usy", "l_arm_shx", "l_arm_ely", "l_arm_elx", "l_arm_uwy", "l_arm_mwx",
  "r_arm_usy", "r_arm_shx", "r_arm_ely", "r_arm_elx", "r_arm_uwy", "r_arm_mwx",
};
const std::size_t kNumJoints = sizeof(kJointNames) / sizeof(kJointNames[0]);
// k_effort's full scale: the joint's torque is the PID's alone.
const unsigned char kPidOnly = 255;
// States waiting for the callback: with the window on there is one at a time; without it, a
// short burst after a stall is answered rather than dropped.
const uint32_t kQueueDepth = 10;
const char kUsage[] =
  "usage: echo_controller [--transport tcp|udp|udp-then-tcp] [--period-ms N]\n"
  "Answers every /atlas/atlas_state with an /atlas/atlas_command stamped with the state's\n"
  "stamp, holding its positions with the gains of atlas_controller/gains.\n"
  "--transport: tcp (default), udp (unreliable only) or udp-then-tcp (unreliable, then reliable)\n"
  "--period-ms: desired_controller_period_ms, 0..255 (default 0: no synchronization window)\n";

class EchoController
{
public:
  EchoController(ros::NodeHandle &nh, const atlas_msgs::AtlasCommand &command,
                 const ros::TransportHints &hints)
    : command_(command)
  {
    publisher_ = nh.advertise<atlas_msgs::AtlasCommand>("/atlas/atlas_command", kQueueDepth);
    subscriber_ = nh.subscribe("/atlas/atlas_state", kQueueDepth, &EchoController::onState,
                               this, hints);
  }

private:
  void onState(const atlas_msgs::AtlasState::ConstPtr &state)
  {
    if (state->position.size() != kNumJoints)
    {
      ROS_WARN_THROTTLE(2.0, "AtlasState with %zu positions, expected %zu; not answered",
                        state->position.size(), kNumJoints);
      return;
    }
    command_.header.stamp = state->header.stamp;
    // AtlasState's positions are float32, AtlasCommand's float64: widened exactly.
    command_.position.assign(state->position.begin(), state->position.end());
    publisher_.publish(command_);
    if (++answered_ == 1)
      ROS_INFO("echo_controller: answering /atlas/atlas_state (first stamp %.3f s)",
               state->header.stamp.toSec());
  }

  atlas_msgs::AtlasCommand command_;
  unsigned long answered_ = 0;
  ros::Publisher publisher_;
  ros::Subscriber subscriber_;
};

bool readGain(ros::NodeHandle &nh, const std::string &joint, const std::string &key, double &value)
{
  const std::string name = "atlas_controller/gains/" + joint + "/" + key;
  if (nh.getParam(name, value))
    return true;
  std::fprintf(stderr, "echo_controller: parameter %s is missing or not a number; load "
               "config/atlas_controller.yaml (atlas.launch does)\n", nh.resolveName(name).c_str());
  return false;
}

// The options after ROS's own are removed; false (and a line on stderr) on a bad one.
bool parseOptions(const std::vector<std::string> &args, std::string &transport, int &period_ms,
                  bool &help)
{
  for (std::size_t i = 1; i < args.size(); ++i)
  {
    const std::string &arg = args[i];
    if (arg == "-h" || arg == "--help")
    {
      help = true;
      return true;
    }
    if (arg != "--transport" && arg != "--period-ms")
    {
      std::fprintf(stderr, "echo_controller: unknown argument '%s'\n%s", arg.c_str(), kUsage);
      return false;
    }
    if (i + 1 >= args.size())
    {
      std::fprintf(stderr, "echo_controller: %s needs a value\n%s", arg.c_str(), kUsage);
      return false;
    }
    const std::string &value = args[++i];
    if (arg == "--transport")
    {
      if (value != "tcp" && value != "udp" && value != "udp-then-tcp")
      {
        std::fprintf(stderr, "echo_controller: --transport is '%s'; expected tcp, udp or "
                     "udp-then-tcp\n", value.c_str());
        return false;
      }
      transport = value;
      continue;
    }
    char *end = nullptr;
    errno = 0;
    const long number = std::strtol(value.c_str(), &end, 10);
    if (value.empty() || *end != '\0' || errno != 0 || number < 0 || number > 255)
    {
      std::fprintf(stderr, "echo_controller: --period-ms is '%s'; expected a whole number of "
                   "milliseconds in 0..255 (desired_controller_period_ms is a uint8)\n",
                   value.c_str());
      return false;
    }
    period_ms = static_cast<int>(number);
  }
  return true;
}

ros::TransportHints hintsFor(const std::string &transport)
{
  if (transport == "udp")
    return ros::TransportHints().unreliable();
  if (transport == "udp-then-tcp")
    return ros::TransportHints().unreliable().reliable().tcpNoDelay(true);
  return ros::TransportHints().tcpNoDelay(true);
}
}  // namespace

int main(int argc, char **argv)
{
  ros::init(argc, argv, "echo_controller");
  std::vector<std::string> args;
  ros::removeROSArgs(argc, argv, args);
  std::string transport = "tcp";
  int period_ms = 0;
  bool help = false;
  if (!parseOptions(args, transport, period_ms, help))
    return 1;
  if (help)
  {
    std::fputs(kUsage, stdout);
    return 0;
  }

  ros::NodeHandle nh;
  atlas_msgs::AtlasCommand command;
  for (std::size_t i = 0; i < kNumJoints; ++i)
  {
    const std::string joint = kJointNames[i];
    double p, i_gain, d, i_clamp;
    if (!readGain(nh, joint, "p", p) || !readGain(nh, joint, "i", i_gain) ||
        !readGain(nh, joint, "d", d) || !readGain(nh, joint, "i_clamp", i_clamp))
      return 1;
    command.position.push_back(0.0);
    command.velocity.push_back(0.0);
    command.effort.push_back(0.0);
    command.kp_position.push_back(p);
    command.ki_position.push_back(i_gain);
    command.kd_position.push_back(d);
    command.kp_velocity.push_back(0.0);
    command.k_effort.push_back(kPidOnly);
    command.i_effort_min.push_back(-i_clamp);
    command.i_effort_max.push_back(i_clamp);
  }
  command.desired_controller_period_ms = static_cast<uint8_t>(period_ms);

  EchoController controller(nh, command, hintsFor(transport));
  ROS_INFO("echo_controller: /atlas/atlas_state over %s, desired_controller_period_ms %d",
           transport.c_str(), period_ms);
  ros::spin();
  return 0;
}
