// What the bag tools say when rosbag cannot read a bag.
#pragma once

#include <rosbag/exceptions.h>

#include <string>

namespace jle {

/// The message for an exception rosbag threw while reading the bag at `path`. A bag cut
/// short (a recorder killed, a full disk) has no index or a record that ends early:
/// rosbag says only "wanted 4 bytes, read 0" or "Bag unindexed", so the repair is named.
/// Other exceptions (an output bag that cannot be written) keep rosbag's words alone.
inline std::string bagReadError(const std::string& path, const rosbag::BagException& e) {
  const std::string what = e.what();
  const bool cut_short = dynamic_cast<const rosbag::BagUnindexedException*>(&e) != nullptr ||
                         dynamic_cast<const rosbag::BagFormatException*>(&e) != nullptr ||
                         what.find("read") != std::string::npos ||
                         what.find("unindexed") != std::string::npos;
  if (!cut_short) return "rosbag: " + what;
  return path + ": " + what +
         " (the bag looks cut short or unindexed, as a recorder that was killed leaves it: "
         "'rosbag reindex " +
         path + "' rebuilds its index, keeping the original as *.orig.bag)";
}

}  // namespace jle
