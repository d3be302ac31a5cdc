// A roscpp client written as DRCSim 2.x controllers were after 2.3: atlas_msgs/AtlasState in,
// atlas_msgs/AtlasCommand out. It waits for ROS time, reads the gains from the parameter
// server, and in answer to each /atlas/atlas_state publishes an AtlasCommand stamped with that
// state's stamp: every joint held at 0 with the parameter gains and k_effort 255 (the PID
// alone), but one arm joint, which follows a sine.
//
// A test node only (test/rostest/atlas_command_client.test): built by catkin for the tests,
// not installed.
//
// Private parameters: ~joint (l_arm_elx), ~amplitude_rad (0.4), ~period_s (4.0): the joint
// follows amplitude * (1 - cos(2 pi t / period)), t from the first state.

#include <cmath>
#include <cstddef>
#include <string>

#include <atlas_msgs/AtlasCommand.h>
#include <atlas_msgs/AtlasState.h>
#include <ros/ros.h>

namespace
{
// The 28 joints in AtlasState's (and the tutorial's) order.
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

class SineClient
{
public:
  SineClient(ros::NodeHandle &nh, const atlas_msgs::AtlasCommand &command,
             std::size_t sine_joint, double amplitude_rad, double period_s)
    : command_(command), sine_joint_(sine_joint), amplitude_rad_(amplitude_rad),
      period_s_(period_s)
  {
    publisher_ = nh.advertise<atlas_msgs::AtlasCommand>("/atlas/atlas_command", 1, true);
    subscriber_ = nh.subscribe("/atlas/atlas_state", 1, &SineClient::onState, this,
                               ros::TransportHints().unreliable().reliable().tcpNoDelay(true));
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
    if (start_.isZero())
      start_ = state->header.stamp;
    const double t_s = (state->header.stamp - start_).toSec();
    command_.header.stamp = state->header.stamp;
    command_.position[sine_joint_] =
      amplitude_rad_ * (1.0 - std::cos(2.0 * M_PI * t_s / period_s_));
    publisher_.publish(command_);
  }

  atlas_msgs::AtlasCommand command_;
  std::size_t sine_joint_;
  double amplitude_rad_;
  double period_s_;
  ros::Time start_;
  ros::Publisher publisher_;
  ros::Subscriber subscriber_;
};

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
  ros::init(argc, argv, "atlas_command_client");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");

  std::string sine_joint_name;
  double amplitude_rad, period_s;
  private_nh.param<std::string>("joint", sine_joint_name, "l_arm_elx");
  private_nh.param("amplitude_rad", amplitude_rad, 0.4);
  private_nh.param("period_s", period_s, 4.0);

  // Under /use_sim_time, ROS time is 0 until the simulator's first /clock.
  ros::Time::waitForValid();

  atlas_msgs::AtlasCommand command;
  std::size_t sine_joint = kNumJoints;
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
    if (joint == sine_joint_name)
      sine_joint = i;
  }
  command.desired_controller_period_ms = 0;  // no synchronization window asked
  if (sine_joint == kNumJoints)
  {
    ROS_FATAL("~joint is %s, not one of Atlas v1's 28 joints", sine_joint_name.c_str());
    return 1;
  }

  SineClient client(nh, command, sine_joint, amplitude_rad, period_s);
  ros::spin();
  return 0;
}
