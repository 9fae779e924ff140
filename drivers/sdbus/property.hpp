// Properties in one line each: a getter generated from an accessor (a member function or data
// pointer, or a captureless lambda) with the D-Bus type deduced from what it returns, after
// systemd's bus_property_get_*() with an offset. Used by dbus/ and the simulator's sim/inspect*.
//
//   property<&TeensyPort::leds>("Leds", kChange, kChangeLeds)
//
// An object's members (methods, properties, signals) are one table of Member; vtable() makes
// the sd_bus_vtable from it, and the table says which properties each change announces.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <systemd/sd-bus.h>
#include <tuple>
#include <type_traits>
#include <vector>

namespace caracara::dbus {

inline constexpr uint64_t kUnpriv = SD_BUS_VTABLE_UNPRIVILEGED; // access is the bus policy's job
inline constexpr uint64_t kChange = SD_BUS_VTABLE_PROPERTY_EMITS_CHANGE;
inline constexpr uint64_t kConst = SD_BUS_VTABLE_PROPERTY_CONST;
inline constexpr uint64_t kFlagBits = (uint64_t{1} << 56) - 1; // sd_bus_vtable::flags is 56 bits wide

// --- The D-Bus type of a C++ type -----------------------------------------------------------

template <size_t N>
using Sig = std::array<char, N>; // NUL-terminated

template <size_t... N>
consteval auto join(const Sig<N>&... parts) {
    Sig<(N + ... + 1) - sizeof...(N)> out{};
    size_t at = 0;
    ((std::copy_n(parts.data(), N - 1, out.data() + at), at += N - 1), ...);
    return out;
}

template <class T, class = void>
struct DBusType; // no D-Bus type for T: cast it in the accessor

template <char C>
struct Basic {
    static constexpr Sig<2> sig{C, '\0'};
};
template <> struct DBusType<bool> : Basic<'b'> {};
template <> struct DBusType<uint8_t> : Basic<'y'> {};
template <> struct DBusType<int16_t> : Basic<'n'> {};
template <> struct DBusType<uint16_t> : Basic<'q'> {};
template <> struct DBusType<int32_t> : Basic<'i'> {};
template <> struct DBusType<uint32_t> : Basic<'u'> {};
template <> struct DBusType<int64_t> : Basic<'x'> {};
template <> struct DBusType<uint64_t> : Basic<'t'> {};
template <> struct DBusType<double> : Basic<'d'> {};
template <> struct DBusType<std::string> : Basic<'s'> {};
template <> struct DBusType<std::string_view> : Basic<'s'> {};
template <> struct DBusType<const char*> : Basic<'s'> {};

template <class T> struct DBusType<std::vector<T>> { static constexpr auto sig = join(Sig<2>{'a', '\0'}, DBusType<T>::sig); };
template <class T, size_t N> struct DBusType<std::array<T, N>> : DBusType<std::vector<T>> {};
template <class T> struct DBusType<std::span<const T>> : DBusType<std::vector<T>> {};
// A tuple is a struct: Orientation's (ddd), Leds' (yyy).
template <class... T>
struct DBusType<std::tuple<T...>> {
    static constexpr auto contents = join(DBusType<T>::sig...);
    static constexpr auto sig = join(Sig<2>{'(', '\0'}, contents, Sig<2>{')', '\0'});
};

template <class T>
inline constexpr auto kSignature = DBusType<std::remove_cvref_t<T>>::sig;

// --- Appending a value ----------------------------------------------------------------------

template <class T>
int append(sd_bus_message* m, const T& v);

template <class T>
int append_elements(sd_bus_message* m, std::span<const T> v) {
    // Fixed-size elements go in one copy; strings and structs one by one.
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
        return sd_bus_message_append_array(m, DBusType<T>::sig[0], v.data(), v.size() * sizeof(T));
    } else {
        int r = sd_bus_message_open_container(m, 'a', kSignature<T>.data());
        for (const T& e : v)
            if (r >= 0)
                r = append(m, e);
        return r < 0 ? r : sd_bus_message_close_container(m);
    }
}

template <class T>
int append(sd_bus_message* m, const T& v) {
    if constexpr (std::is_same_v<T, bool>) {
        const int b = v;
        return sd_bus_message_append_basic(m, 'b', &b);
    } else if constexpr (std::is_arithmetic_v<T>) {
        return sd_bus_message_append_basic(m, DBusType<T>::sig[0], &v);
    } else if constexpr (std::is_same_v<T, std::string>) {
        return sd_bus_message_append_basic(m, 's', v.c_str());
    } else if constexpr (std::is_same_v<T, std::string_view>) {
        return append(m, std::string(v)); // sd-bus wants it NUL-terminated
    } else if constexpr (std::is_same_v<T, const char*>) {
        return sd_bus_message_append_basic(m, 's', v);
    } else if constexpr (requires { std::tuple_size<T>::value; typename T::value_type; }) { // std::array
        return append_elements(m, std::span<const typename T::value_type>(v));
    } else if constexpr (requires { typename T::value_type; }) { // std::vector, std::span
        return append_elements(m, std::span<const typename T::value_type>(v.data(), v.size()));
    } else { // std::tuple
        int r = sd_bus_message_open_container(m, 'r', DBusType<T>::contents.data());
        std::apply([&](const auto&... e) { ((r = r < 0 ? r : append(m, e)), ...); }, v);
        return r < 0 ? r : sd_bus_message_close_container(m);
    }
}

// --- The value in bytes, to tell whether it changed since it was announced -------------------

template <class T>
void encode(std::string& out, const T& v) {
    if constexpr (std::is_arithmetic_v<T>) {
        out.append(reinterpret_cast<const char*>(&v), sizeof v);
    } else if constexpr (std::is_same_v<T, std::string> || std::is_same_v<T, std::string_view> ||
                         std::is_same_v<T, const char*>) {
        const std::string_view s(v);
        encode(out, s.size());
        out.append(s);
    } else if constexpr (requires { typename T::value_type; }) {
        encode(out, std::size(v));
        for (const auto& e : v)
            encode(out, e);
    } else {
        std::apply([&](const auto&... e) { (encode(out, e), ...); }, v);
    }
}

// --- Getters from accessors -----------------------------------------------------------------

// The object an accessor reads, as its first argument takes it (const or not: the simulator's
// models hand out their parts through non-const accessors).
template <auto Get, class = void>
struct Accessor; // a lambda
template <class C, class R, R (C::*Get)() const>
struct Accessor<Get> {
    using Arg = const C&;
};
template <class C, class R, R C::*Get>
    requires(!std::is_function_v<R>)
struct Accessor<Get> {
    using Arg = const C&;
};
template <auto Get>
    requires requires { &decltype(Get)::operator(); }
struct Accessor<Get> {
    template <class R, class L, class A>
    static A arg(R (L::*)(A) const);
    using Arg = decltype(arg(&decltype(Get)::operator()));
};

template <auto Get>
using Arg = typename Accessor<Get>::Arg;
template <auto Get>
using Value = std::remove_cvref_t<std::invoke_result_t<decltype(Get), Arg<Get>>>;

template <auto Get>
decltype(auto) read(void* userdata) {
    return std::invoke(Get, *static_cast<std::remove_reference_t<Arg<Get>>*>(userdata));
}

template <auto Get>
int get(sd_bus*, const char*, const char*, const char*, sd_bus_message* reply, void* userdata, sd_bus_error*) {
    return append(reply, read<Get>(userdata));
}

template <auto Get>
void encode_property(void* userdata, std::string& out) {
    encode(out, read<Get>(userdata));
}

// --- An object's table ----------------------------------------------------------------------

// One method, property or signal; `announce` = the change flags that announce a property.
struct Member {
    sd_bus_vtable entry;
    uint32_t announce = 0;
    void (*encode)(void* userdata, std::string& out) = nullptr;
};

template <auto Get>
constexpr Member property(const char* name, uint64_t flags = 0, uint32_t announce = 0) {
    return {SD_BUS_PROPERTY(name, kSignature<Value<Get>>.data(), get<Get>, 0, flags & kFlagBits), announce, encode_property<Get>};
}

constexpr Member member(const sd_bus_vtable& entry) { return {entry}; }

// The vtable of `members`: START, the members in order, END (entry i + 1 is members[i]).
// A property announces changes exactly when its flags promise it (the contract's EmitsChangedSignal).
template <size_t N>
consteval std::array<sd_bus_vtable, N + 2> vtable(const Member (&members)[N]) {
    static_assert(N <= 64, "AnnouncedObject keeps the members to announce in a 64-bit mask");
    std::array<sd_bus_vtable, N + 2> v{{SD_BUS_VTABLE_START(0)}};
    for (size_t i = 0; i < N; ++i) {
        const bool emits = members[i].entry.type == _SD_BUS_VTABLE_PROPERTY && (members[i].entry.flags & kChange);
        if (emits != (members[i].announce != 0))
            throw "a property is announced if and only if it is declared with kChange";
        v[i + 1] = members[i].entry;
    }
    v[N + 1] = SD_BUS_VTABLE_END;
    return v;
}

} // namespace caracara::dbus
