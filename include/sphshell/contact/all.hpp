#pragma once
// Every part of the contact family.

#include <sphshell/contact/body_set.hpp>
#include <sphshell/contact/contact.hpp>
#include <sphshell/contact/cylinder.hpp>
#include <sphshell/contact/penalty.hpp>
#include <sphshell/contact/plane.hpp>
#include <sphshell/contact/rigid_body.hpp>
#include <sphshell/contact/shell_contact.hpp>
#include <sphshell/contact/sphere.hpp>
#include <sphshell/contact/surface_mesh.hpp>
#include <sphshell/contact/triangle_surface.hpp>
