#include <joint_load_estimator/ros/conversions.hpp>
#include <joint_load_estimator/ros/external_outputs.hpp>

#include <algorithm>

namespace jle {

void toWrenchMessage(const ContactEstimate& contact, Stamp stamp,
                     geometry_msgs::WrenchStamped& msg) {
  msg.header.stamp = toRosTime(stamp);
  msg.header.frame_id = contact.link;
  msg.wrench.force.x = contact.force.x();
  msg.wrench.force.y = contact.force.y();
  msg.wrench.force.z = contact.force.z();
  msg.wrench.torque.x = contact.moment.x();
  msg.wrench.torque.y = contact.moment.y();
  msg.wrench.torque.z = contact.moment.z();
}

void toContactMessage(const LoadsRecord& record, joint_load_estimator::Contact& msg) {
  msg.header.stamp = toRosTime(record.stamp);
  msg.in_contact = record.in_contact;
  msg.joint = record.contact_joint;
  msg.link = record.contact_link;
  msg.contacts.clear();
  if (!record.in_contact) return;
  for (const ContactEstimate& c : record.contacts)
    if (c.active) msg.contacts.push_back(c.link);
}

void ExternalOutputs::advertise(ros::NodeHandle& private_nh, const LoadsRecord& record) {
  enabled_ = !record.external_effort.empty();
  if (!enabled_) return;
  for (const ContactEstimate& c : record.contacts)
    wrench_pubs_.push_back(
        private_nh.advertise<geometry_msgs::WrenchStamped>("external_wrench/" + c.link, 10));
  contact_pub_ = private_nh.advertise<joint_load_estimator::Contact>("contact", 10, true);
}

void ExternalOutputs::publish(const LoadsRecord& record) {
  if (!enabled_) return;
  for (std::size_t k = 0; k < wrench_pubs_.size(); ++k) {
    worst_conditioning_ = std::min(worst_conditioning_, record.contacts[k].conditioning);
    if (wrench_pubs_[k].getNumSubscribers() == 0) continue;
    toWrenchMessage(record.contacts[k], record.stamp, wrench_msg_);
    wrench_pubs_[k].publish(wrench_msg_);
  }
  in_contact_ = record.in_contact;
  if (!isContactEvent(record)) return;
  if (record.contact_started) ++contacts_;
  joint_ = record.contact_joint;
  link_ = record.contact_link;
  toContactMessage(record, contact_msg_);
  contact_pub_.publish(contact_msg_);
}

void ExternalOutputs::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  if (!enabled_) return;
  if (in_contact_)
    status.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN,
                        "in contact at joint '" + joint_ + "' (link '" + link_ + "')");
  status.add("contacts started", contacts_);
  if (!wrench_pubs_.empty()) status.add("worst contact Jacobian conditioning", worst_conditioning_);
  worst_conditioning_ = 1.0;
}

}  // namespace jle
