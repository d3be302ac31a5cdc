// atlas_recorder: records topics to a bag like `rosbag record -o PREFIX TOPIC...`, without
// losing messages under load.
//
// Why not `rosbag record` itself: it subscribes with a hard-coded queue of 100 messages per
// topic and drops the oldest when its callback thread falls behind. On a 2-core machine, three
// clients commanding at 2 kHz each beside the simulator made it lose 6-25 % of
// /atlas/joint_commands. Here each subscription queue is deep (kQueueDepth), so a busy moment
// delays messages instead of dropping them; they are written with the time they arrived. The
// bag is written with rosbag's own C++ storage API (librosbag_storage), so it is a standard
// bag v2.0: `NAME.bag.active` while recording, closed, indexed and renamed to `NAME.bag` on
// SIGINT or SIGTERM, after the messages already received have been written.
//
// Chunks are compressed as `rosbag record --lz4` / `--bz2` compress them (rosbag's own
// compression, so `rosbag info` shows it and every bag reader decompresses it). lz4 halves
// the bag for no measurable CPU; bz2 saves a tenth more for ~25 us a message (bench/README.md).
// The 1 kHz float64s change in their low bits every step: little more compresses.
//
// usage: atlas_recorder [--compression none|lz4|bz2] PREFIX TOPIC... [ROS remappings]
//   writes PREFIX_<YYYY-MM-DD-HH-MM-SS>.bag, as `rosbag record -o PREFIX` does; chunks are
//   not compressed unless --compression says so.

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <optional>
#include <string>
#include <vector>

#include <boost/bind/bind.hpp>
#include <boost/make_shared.hpp>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <topic_tools/shape_shifter.h>

namespace
{
using RecordedEvent = ros::MessageEvent<topic_tools::ShapeShifter const>;

// Messages each topic may have waiting to be written: 200 s of 1 kHz joint states, 33 s of a
// 6 kHz command flood (up to ~500 MB of commands). The recorder runs at niceness 10, so a
// machine kept busy by other work starves it for as long as the load lasts; it catches up
// afterwards. Beyond the bound roscpp drops the oldest, as rosbag record does past 100: a
// recorder slower than the simulator for good (real_time_factor 0 on a small machine) must
// not grow without bound.
constexpr uint32_t kQueueDepth = 200000;
// After SIGINT: stop after kQuietWaits empty waits of kDrainWaitS (s) in a row (1 s when the
// recorder gets the CPU), or after kDrainMaxS (s, wall).
constexpr double kDrainWaitS = 0.05;
constexpr int kQuietWaits = 20;
constexpr double kDrainMaxS = 10.0;
// While recording, the queue is emptied every kBatchPeriodS (s, wall) instead of waking on each
// message: a message's receipt time is taken when it arrives (by roscpp's poll thread), not
// when it is written, so the bag is the same; waking the writing thread for each of the
// simulator's ~13 messages a millisecond cost more CPU than writing them (bench/README.md).
constexpr double kBatchPeriodS = 0.005;

std::atomic<bool> g_stop_requested(false);

void requestStop(int /*signal*/)
{
  g_stop_requested = true;
}

// The chunk compression named NAME (as the launch's `compression` argument spells it).
std::optional<rosbag::CompressionType> compressionNamed(const std::string& name)
{
  if (name == "none")
    return rosbag::compression::Uncompressed;
  if (name == "lz4")
    return rosbag::compression::LZ4;
  if (name == "bz2")
    return rosbag::compression::BZ2;
  return std::nullopt;
}

std::string timestampedName(const std::string& prefix)
{
  std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof(stamp), "%Y-%m-%d-%H-%M-%S", std::localtime(&now));
  return prefix + "_" + stamp + ".bag";
}

// Writes every received message to the bag with the time it arrived; any write error stops the
// recording. Under sim time, ros::Time::now() is zero until the first /clock: messages that
// arrive before it (latched ones, the simulator's first steps) are kept and written with the
// first valid time, where `rosbag record` waits for a valid time before subscribing and so
// never sees them.
class BagWriter
{
public:
  explicit BagWriter(rosbag::Bag& bag) : bag_(bag) {}

  void write(const RecordedEvent& event, const std::string& topic)
  {
    const ros::Time received = event.getReceiptTime();
    if (received < ros::TIME_MIN)
    {
      early_.emplace_back(topic, event);
      return;
    }
    for (const auto& [early_topic, early_event] : early_)
      writeAt(early_topic, early_event, received);
    early_.clear();
    writeAt(topic, event, received);
  }

  bool failed() const { return failed_; }
  const std::string& reason() const { return reason_; }
  unsigned long written() const { return written_; }
  size_t unwritten() const { return early_.size(); }

private:
  void writeAt(const std::string& topic, const RecordedEvent& event, const ros::Time& time)
  {
    if (failed_)
      return;
    try
    {
      bag_.write(topic, time, event.getConstMessage(), event.getConnectionHeaderPtr());
      ++written_;
    }
    catch (const rosbag::BagException& error)
    {
      // errno still holds why the write failed (ENOSPC, EFBIG); rosbag's text does not say.
      const int cause = errno;
      reason_ = cause != 0 ? std::strerror(cause) : error.what();
      // On a full disk `rosbag reindex` cannot make its backup copy (and still exits 0):
      // it must write elsewhere.
      ROS_ERROR("atlas_recorder: recording stopped: cannot write %s to %s (%s); the bag holds "
                "the run up to here: `rosbag reindex %s%s` to read it",
                topic.c_str(), bag_.getFileName().c_str(), reason_.c_str(),
                cause == ENOSPC ? "--output-dir DIR_WITH_ROOM " : "", bag_.getFileName().c_str());
      failed_ = true;
      g_stop_requested = true;
    }
  }

  rosbag::Bag& bag_;
  std::vector<std::pair<std::string, RecordedEvent>> early_;
  bool failed_ = false;
  std::string reason_;
  unsigned long written_ = 0;
};

// The directory part of `path` ("." for a bare file name).
std::string bagDirOf(const std::string& path)
{
  const std::string::size_type slash = path.rfind('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

ros::Subscriber subscribeAnyType(ros::NodeHandle& node, const std::string& topic, BagWriter& writer)
{
  ros::SubscribeOptions options;
  options.topic = topic;
  options.queue_size = kQueueDepth;
  options.md5sum = ros::message_traits::md5sum<topic_tools::ShapeShifter>();
  options.datatype = ros::message_traits::datatype<topic_tools::ShapeShifter>();
  options.helper = boost::make_shared<ros::SubscriptionCallbackHelperT<const RecordedEvent&>>(
      boost::bind(&BagWriter::write, &writer, boost::placeholders::_1, topic));
  options.transport_hints = ros::TransportHints().tcpNoDelay();
  return node.subscribe(options);
}
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "recorder", ros::init_options::NoSigintHandler);
  std::vector<std::string> args;
  ros::removeROSArgs(argc, argv, args);
  const bool help = args.size() >= 2 && (args[1] == "-h" || args[1] == "--help");
  std::string compression_name = "none";
  rosbag::CompressionType compression = rosbag::compression::Uncompressed;
  if (!help && args.size() >= 3 && args[1] == "--compression")
  {
    compression_name = args[2];
    const std::optional<rosbag::CompressionType> named = compressionNamed(compression_name);
    if (!named)
    {
      std::fprintf(stderr, "atlas_recorder: unknown compression '%s' (expected none, lz4 or bz2)\n",
                   args[2].c_str());
      return 1;
    }
    compression = *named;
    args.erase(args.begin() + 1, args.begin() + 3);
  }
  if (help || args.size() < 3)
  {
    std::fprintf(help ? stdout : stderr,
                 "usage: atlas_recorder [--compression none|lz4|bz2] PREFIX TOPIC...\n"
                 "Records TOPICs to PREFIX_<date-time>.bag without dropping messages; SIGINT closes it.\n"
                 "--compression: rosbag's chunk compression (default: none).\n");
    return help ? 0 : 1;
  }
  const std::string bag_path = timestampedName(args[1]);
  const std::string active_path = bag_path + ".active";

  rosbag::Bag bag;
  try
  {
    bag.open(active_path, rosbag::bagmode::Write);
    bag.setCompression(compression);
  }
  catch (const rosbag::BagException& error)
  {
    std::fprintf(stderr, "atlas_recorder: cannot open %s: %s\n", active_path.c_str(), error.what());
    return 1;
  }
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);
  // Past a file-size limit (ulimit -f), a write fails with EFBIG, reported as a full disk is,
  // instead of SIGXFSZ killing the recorder with the bag unindexed and nothing said.
  std::signal(SIGXFSZ, SIG_IGN);

  ros::NodeHandle node;
  BagWriter writer(bag);
  std::vector<ros::Subscriber> subscribers;
  for (size_t i = 2; i < args.size(); ++i)
    subscribers.push_back(subscribeAnyType(node, args[i], writer));
  ROS_INFO("atlas_recorder: recording %zu topics to %s (chunk compression: %s)", subscribers.size(),
           bag_path.c_str(), compression_name.c_str());

  ros::CallbackQueue* callbacks = ros::getGlobalCallbackQueue();
  while (!g_stop_requested && ros::ok())
  {
    callbacks->callAvailable(ros::WallDuration(0));
    ros::WallDuration(kBatchPeriodS).sleep();
  }

  // Write what has already arrived, and what is still arriving: a recorder starved of CPU is
  // behind, and what the publishers sent before they stopped may still be in its sockets. Drain
  // until kQuietWaits waits of kDrainWaitS in a row bring nothing (counted in waits, not wall
  // time, so that a starved recorder is not cut short), kDrainMaxS at most (roslaunch
  // escalates to SIGTERM after 15 s, to SIGKILL 2 s later, which leaves the bag unindexed).
  // Then stop receiving (shutting a subscriber down first would discard its queued messages).
  // callAvailable(), not callOne(): a batch under way is written to its end, past kDrainMaxS if
  // need be. (With callOne() here and above, a fresh-clone load test once lost 15 of 183 001
  // commands, cause not pinned down; callAvailable() is what every earlier run passed with.)
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(kDrainMaxS);
  unsigned long seen = writer.written();
  for (int quiet = 0; quiet < kQuietWaits && ros::WallTime::now() < give_up && !writer.failed();)
  {
    callbacks->callAvailable(ros::WallDuration(kDrainWaitS));
    if (writer.written() != seen)
    {
      seen = writer.written();
      quiet = 0;
    }
    else
    {
      ++quiet;
    }
  }
  // What is still queued after kDrainMaxS is dropped at once: unsubscribing removes a
  // subscription's queued callbacks one deque erase at a time, which with hundreds of
  // thousands queued took longer than roslaunch waits before SIGKILL (an unindexed bag; bz2
  // chunks at real_time_factor 0 on a busy machine).
  const bool gave_up = !callbacks->isEmpty();
  if (gave_up)
    callbacks->clear();
  for (ros::Subscriber& subscriber : subscribers)
    subscriber.shutdown();
  try
  {
    bag.close();  // writes the last chunk and the index: fails again on a full disk
  }
  catch (const rosbag::BagException& error)
  {
    if (!writer.failed())
      std::fprintf(stderr, "atlas_recorder: cannot close %s: %s; `rosbag reindex %s` to read it\n",
                   active_path.c_str(), error.what(), active_path.c_str());
    ros::shutdown();
    // Not `return`: rosbag::Bag's destructor would try to close it again and throw from a
    // destructor (std::terminate, an abort and a core dump on top of the one line said).
    std::fflush(nullptr);
    std::_Exit(1);
  }
  if (gave_up && !writer.failed())
    std::fprintf(stderr, "atlas_recorder: stopped writing after %.0f s of draining with messages "
                 "still queued (the recorder was behind); they are not in the bag\n", kDrainMaxS);
  ros::shutdown();
  if (writer.failed())  // said in one line when it happened
    return 1;
  if (writer.written() == 0)
  {
    // No message with a valid (sim) time: the simulator never ran (its launch stopped before
    // it was ready). An empty bag would only become "the newest bag" of the bag tools.
    if (std::remove(active_path.c_str()) != 0)
    {
      std::perror(("atlas_recorder: cannot remove " + active_path).c_str());
      return 1;
    }
    std::printf("atlas_recorder: no message to write (the simulator never published a sim time); "
                "no bag left in %s\n", bagDirOf(bag_path).c_str());
    return 0;
  }
  if (std::rename(active_path.c_str(), bag_path.c_str()) != 0)
  {
    std::perror(("atlas_recorder: cannot rename " + active_path).c_str());
    return 1;
  }
  if (writer.unwritten() > 0)
    std::printf("atlas_recorder: %zu messages arrived before the first valid (sim) time and were not "
                "written\n", writer.unwritten());
  std::printf("atlas_recorder: wrote %lu messages to %s\n", writer.written(), bag_path.c_str());
  return 0;
}
