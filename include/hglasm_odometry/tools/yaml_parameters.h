// YAML parameter files read the way rosparam (and roslaunch's <rosparam command="load">) reads them,
// into the XmlRpc tree the parameter server would hold, without Python or a master.
//
// Plain scalars are typed by YAML 1.1's rules as PyYAML applies them (ints stay ints: 3, 0x1f, 010, 1:30;
// floats need a dot: 1.0e-06, .inf; yes/no/on/off are bools; 1e-3 is a string), quoted and block scalars
// are strings, and rosparam's angles are converted: deg(90), !degrees 90, rad(pi/2), !radians 2*pi.
// Anchors, aliases and merge keys (<<) work as in PyYAML. What the parameter server cannot hold is an
// error naming the file and line: null values, keys that are not strings, ints beyond 32 bits,
// timestamps and other tags.
#pragma once

#include <string>

#include <xmlrpcpp/XmlRpcValue.h>

namespace hglasm_odometry {

/// Parses YAML text (the first document; none: an empty struct) into *value. `source` names the text
/// in error messages (e.g. the file name). False with *error set on a syntax error or an unsupported
/// value.
bool parseYamlParameters(const std::string& text, const std::string& source, XmlRpc::XmlRpcValue* value,
                         std::string* error);

/// Reads a parameter file: as above, and the top level must be a mapping (a dictionary of parameters).
/// rosparam's namespace key `_ns` at the top level is dropped, as rosparam.load_file does.
bool loadYamlParameters(const std::string& path, XmlRpc::XmlRpcValue* value, std::string* error);

}  // namespace hglasm_odometry
