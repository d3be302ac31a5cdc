// A roscpp client of the simulator, as DRCSim's C++ example clients were written: it waits
// for ROS time, reads the gains from the parameter server, and in answer to each
// /atlas/joint_states publishes an osrf_msgs/JointCommands stamped with that state's stamp,
// holding every joint at 0 but one arm joint, which follows a sine.
//
// A test node only (test/rostest/cpp_client.test): built by catkin for the tests, not installed.
//
// Private parameters: ~joint (l_arm_elx), ~amplitude_rad (0.4), ~period_s (4.0): the joint
// follows amplitude * (1 - cos(2 pi t / period)), t from the first joint state.
// ~transport: how /atlas/joint_states is asked for: udp_tcp (default, DRCSim's own clients:
// .unreliable().reliable(), UDP preferred), udp (DRCSim's C++ tutorial: .unreliable() only)
// or tcp (.reliable()); ~max_datagram_size (bytes, 0: roscpp's 1500) for UDP: below a joint
// state's 1067 bytes, each comes in blocks that roscpp reassembles.

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <osrf_msgs/JointCommands.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>

namespace
{
// The 28 joints in the tutorial's (and DRCSim's) order.
const char *const kJointNames[] = {
  "back_lbz", "back_mby", "back_ubx", "neck_ay",
  "l_leg_uhz", "l_leg_mhx", "l_leg_lhy", "l_leg_kny", "l_leg_uay", "l_leg_lax",
  "r_leg_uhz", "r_leg_mhx", "r_leg_lhy", "r_leg_kny", "r_leg_uay", "r_leg_lax",
  "l_arm_usy", "l_arm_shx", "l_arm_ely", "l_arm_elx", "l_arm_uwy", "l_arm_mwx",
  "r_arm_usy", "r_arm_shx", "r_arm_ely", "r_arm_elx", "r_arm_uwy", "r_arm_mwx",
};
const std::size_t kNumJoints = sizeof(kJointNames) / sizeof(kJointNames[0]);

class SineClient
{
public:
  SineClient(ros::NodeHandle &nh, const osrf_msgs::JointCommands &command, std::size_t sine_joint,
             double amplitude_rad, double period_s, const ros::TransportHints &hints)
    : command_(command), sine_joint_(sine_joint), amplitude_rad_(amplitude_rad),
      period_s_(period_s)
  {
    // Latched, as DRCSim's examples: a late-connecting simulator still gets the last command.
    publisher_ = nh.advertise<osrf_msgs::JointCommands>("/atlas/joint_commands", 1, true);
    subscriber_ = nh.subscribe("/atlas/joint_states", 1, &SineClient::onJointState, this, hints);
  }

private:
  void onJointState(const sensor_msgs::JointState::ConstPtr &state)
  {
    if (start_.isZero())
      start_ = state->header.stamp;
    const double t_s = (state->header.stamp - start_).toSec();
    command_.header.stamp = state->header.stamp;
    command_.position[sine_joint_] =
      amplitude_rad_ * (1.0 - std::cos(2.0 * M_PI * t_s / period_s_));
    publisher_.publish(command_);
  }

  osrf_msgs::JointCommands command_;
  std::size_t sine_joint_;
  double amplitude_rad_;
  double period_s_;
  ros::Time start_;
  ros::Publisher publisher_;
  ros::Subscriber subscriber_;
};

// The transport hints ~transport names; false for an unknown name.
bool transportHints(const std::string &transport, int max_datagram_size,
                    ros::TransportHints &hints)
{
  if (transport == "udp_tcp")
    hints = ros::TransportHints().unreliable().reliable().tcpNoDelay(true);
  else if (transport == "udp")
    hints = ros::TransportHints().unreliable();
  else if (transport == "tcp")
    hints = ros::TransportHints().reliable().tcpNoDelay(true);
  else
    return false;
  if (max_datagram_size > 0)
    hints.maxDatagramSize(max_datagram_size);
  return true;
}

bool readGain(ros::NodeHandle &nh, const std::string &joint, const std::string &key, double &value)
{
  const std::string name = "atlas_controller/gains/" + joint + "/" + key;
  if (nh.getParam(name, value))
    return true;
  ROS_FATAL("parameter %s is missing or not a number; load config/atlas_controller.yaml",
            nh.resolveName(name).c_str());
  return false;
}
}  // namespace

int main(int argc, char **argv)
{
  ros::init(argc, argv, "joint_commands_client");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");

  std::string sine_joint_name;
  double amplitude_rad, period_s;
  private_nh.param<std::string>("joint", sine_joint_name, "l_arm_elx");
  private_nh.param("amplitude_rad", amplitude_rad, 0.4);
  private_nh.param("period_s", period_s, 4.0);
  std::string transport;
  private_nh.param<std::string>("transport", transport, "udp_tcp");
  int max_datagram_size;
  private_nh.param("max_datagram_size", max_datagram_size, 0);
  ros::TransportHints hints;
  if (!transportHints(transport, max_datagram_size, hints))
  {
    ROS_FATAL("~transport is %s, not one of udp_tcp, udp, tcp", transport.c_str());
    return 1;
  }

  // Under /use_sim_time, ROS time is 0 until the simulator's first /clock.
  ros::Time::waitForValid();

  osrf_msgs::JointCommands command;
  std::size_t sine_joint = kNumJoints;
  for (std::size_t i = 0; i < kNumJoints; ++i)
  {
    const std::string joint = kJointNames[i];
    double p, i_gain, d, i_clamp;
    if (!readGain(nh, joint, "p", p) || !readGain(nh, joint, "i", i_gain) ||
        !readGain(nh, joint, "d", d) || !readGain(nh, joint, "i_clamp", i_clamp))
      return 1;
    command.name.push_back("atlas::" + joint);
    command.position.push_back(0.0);
    command.velocity.push_back(0.0);
    command.effort.push_back(0.0);
    command.kp_position.push_back(p);
    command.ki_position.push_back(i_gain);
    command.kd_position.push_back(d);
    command.kp_velocity.push_back(0.0);
    command.i_effort_min.push_back(-i_clamp);
    command.i_effort_max.push_back(i_clamp);
    if (joint == sine_joint_name)
      sine_joint = i;
  }
  if (sine_joint == kNumJoints)
  {
    ROS_FATAL("~joint is %s, not one of Atlas v1's 28 joints", sine_joint_name.c_str());
    return 1;
  }

  SineClient client(nh, command, sine_joint, amplitude_rad, period_s, hints);
  ros::spin();
  return 0;
}
