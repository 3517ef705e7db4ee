#include <joint_load_estimator/ros/settings.hpp>

#include <string>

namespace jle {

ParamValue fromXmlRpc(const XmlRpc::XmlRpcValue& value) {
  using XmlRpc::XmlRpcValue;
  XmlRpcValue& v = const_cast<XmlRpcValue&>(value);  // XmlRpc's casts are not const
  switch (v.getType()) {
    case XmlRpcValue::TypeInvalid: return ParamValue();
    case XmlRpcValue::TypeBoolean: return ParamValue(static_cast<bool>(v));
    case XmlRpcValue::TypeInt: return ParamValue(static_cast<int>(v));
    case XmlRpcValue::TypeDouble: return ParamValue(static_cast<double>(v));
    case XmlRpcValue::TypeString: return ParamValue(static_cast<std::string>(v));
    case XmlRpcValue::TypeArray: {
      ParamValue out = ParamValue::list();
      for (int i = 0; i < v.size(); ++i) out.push(fromXmlRpc(v[i]));
      return out;
    }
    case XmlRpcValue::TypeStruct: {
      ParamValue out = ParamValue::map();
      for (auto it = v.begin(); it != v.end(); ++it) out.set(it->first, fromXmlRpc(it->second));
      return out;
    }
    default: throw SettingsError("a parameter is a date or binary data: not a setting");
  }
}

Settings parseSettings(const XmlRpc::XmlRpcValue& params) {
  return parseSettings(fromXmlRpc(params));
}

}  // namespace jle
