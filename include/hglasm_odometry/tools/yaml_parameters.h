// Parameter YAML files read into a ParameterTree holding what the parameter server would hold after
// rosparam (and roslaunch's <rosparam command="load">) loaded them, without Python or a master, so that the
// offline tools and the nodelet share one loader (hglasm_odometry::loadOptions over a ParameterSource).
//
// yaml-cpp parses; plain scalars are typed as rosparam types them for the forms a parameter file needs:
// YAML 1.1 bools (true/false, yes/no, on/off), decimal ints (32-bit), floats with a dot (1.0e-4, .5, 3.),
// .inf/-.inf/.nan, and deg(NUMBER)/rad(NUMBER); quoted and block scalars and other plain text are strings;
// anchors and aliases work. What rosparam would read another way (1e-3 is a string to it, 010 is 8, 1:30
// is 90) or the parameter server cannot hold (nulls, keys that are not strings, merge keys, tags) is an
// error naming the file, the line and the key.
#pragma once

#include <string>

#include "hglasm_odometry/core/parameter_source.h"

namespace hglasm_odometry {

/// Reads a parameter file whose top level is a mapping (or empty) into *tree; rosparam's namespace key
/// `_ns` at the top level is dropped, as rosparam.load_file does. False with *error set.
bool loadYamlParameters(const std::string& path, hglasm::ParameterTree* tree, std::string* error);

}  // namespace hglasm_odometry
