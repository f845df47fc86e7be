// An element's properties declared once each: id, name, blurb, range, flags
// and the settings member it reads and writes (its default is the member's
// initial value), instead of the same name in four switches. set() and get()
// serve GObject's set_property and get_property.
#pragma once

#include <gst/gst.h>

#include <functional>
#include <map>
#include <string>
#include <type_traits>
#include <utility>

// The settings member a property reads and writes: SETTING(follow.steering.kp).
#define SETTING(path) \
  [](auto& settings) -> auto& { return settings.path; }

namespace wircam::gst {

// "steering-kp" → "Steering kp": the nick gst-inspect shows as the title.
const char* nickOf(const char* name);

template <typename Settings>
class PropertyTable {
 public:
  // Properties are installed on `klass` as they are declared.
  void installOn(GObjectClass* klass) { klass_ = klass; }

  // `member` is SETTING(field), a guint, gint or double.
  template <typename Member>
  void number(guint id, const char* name, const char* blurb, double min, double max, Member member,
              GParamFlags flags) {
    using T = std::remove_cvref_t<decltype(member(defaults_))>;
    T initial = member(defaults_);
    GParamSpec* spec;
    if constexpr (std::is_same_v<T, guint>)
      spec = g_param_spec_uint(name, nickOf(name), blurb, static_cast<guint>(min),
                               static_cast<guint>(max), initial, flags);
    else if constexpr (std::is_same_v<T, gint>)
      spec = g_param_spec_int(name, nickOf(name), blurb, static_cast<gint>(min),
                              static_cast<gint>(max), initial, flags);
    else
      spec = g_param_spec_double(name, nickOf(name), blurb, min, max, initial, flags);
    add(id, spec, member);
  }

  template <typename Member>  // a bool field
  void boolean(guint id, const char* name, const char* blurb, Member member, GParamFlags flags) {
    add(id, g_param_spec_boolean(name, nickOf(name), blurb, member(defaults_), flags), member);
  }

  // A string field; NULL sets the default back.
  template <typename Member>
  void string(guint id, const char* name, const char* blurb, Member member, GParamFlags flags) {
    add(id, g_param_spec_string(name, nickOf(name), blurb, member(defaults_).c_str(), flags),
        member);
  }

  // An enum field, registered as `type`.
  template <typename Member>
  void choice(guint id, const char* name, const char* blurb, GType type, Member member,
              GParamFlags flags) {
    add(id,
        g_param_spec_enum(name, nickOf(name), blurb, type, static_cast<gint>(member(defaults_)),
                          flags),
        member);
  }

  // False when `id` is not one of the table's (the element's own then).
  bool set(guint id, const GValue* value, Settings& settings) const {
    auto entry = entries_.find(id);
    if (entry == entries_.end()) return false;
    entry->second.set(settings, value);
    return true;
  }

  bool get(guint id, const Settings& settings, GValue* value) const {
    auto entry = entries_.find(id);
    if (entry == entries_.end()) return false;
    entry->second.get(settings, value);
    return true;
  }

 private:
  struct Entry {
    std::function<void(Settings&, const GValue*)> set;
    std::function<void(const Settings&, GValue*)> get;
  };

  template <typename Member>
  void add(guint id, GParamSpec* spec, Member member) {
    using T = std::remove_cvref_t<decltype(member(defaults_))>;
    g_object_class_install_property(klass_, id, spec);
    T initial = member(defaults_);
    entries_[id] = {[member, initial](Settings& s, const GValue* value) {
                      member(s) = read<T>(value, initial);
                    },
                    [member](const Settings& s, GValue* value) { write(value, member(s)); }};
  }

  template <typename T>
  static T read(const GValue* value, const T& initial) {
    if constexpr (std::is_same_v<T, guint>)
      return g_value_get_uint(value);
    else if constexpr (std::is_same_v<T, gint>)
      return g_value_get_int(value);
    else if constexpr (std::is_same_v<T, double>)
      return g_value_get_double(value);
    else if constexpr (std::is_same_v<T, bool>)
      return g_value_get_boolean(value) != FALSE;
    else if constexpr (std::is_same_v<T, std::string>)
      return g_value_get_string(value) ? std::string(g_value_get_string(value)) : initial;
    else
      return static_cast<T>(g_value_get_enum(value));
  }

  template <typename T>
  static void write(GValue* value, const T& field) {
    if constexpr (std::is_same_v<T, guint>)
      g_value_set_uint(value, field);
    else if constexpr (std::is_same_v<T, gint>)
      g_value_set_int(value, field);
    else if constexpr (std::is_same_v<T, double>)
      g_value_set_double(value, field);
    else if constexpr (std::is_same_v<T, bool>)
      g_value_set_boolean(value, field);
    else if constexpr (std::is_same_v<T, std::string>)
      g_value_set_string(value, field.c_str());
    else
      g_value_set_enum(value, static_cast<gint>(field));
  }

  GObjectClass* klass_ = nullptr;
  Settings defaults_;
  std::map<guint, Entry> entries_;
};

}  // namespace wircam::gst
