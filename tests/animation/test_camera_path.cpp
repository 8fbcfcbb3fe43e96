// tests/animation/test_camera_path.cpp — the camera-path maths of `vdbsplat animate`:
// zoom spacing geometric and hitting both ends, orbit radius constant, keyframe spline
// through every key and C¹ in time, the strict keyframe parser (one Error naming the file).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "animation/camera_path.h"
#include "util/error.h"

namespace vdbsplat::animation {
namespace {

TEST(Zoom, GeometricAndHitsBothEnds) {
    const auto d = zoomDistances(8.0, 0.125, 48);
    ASSERT_EQ(d.size(), 48u);
    EXPECT_DOUBLE_EQ(d.front(), 8.0);
    EXPECT_DOUBLE_EQ(d.back(), 0.125);
    const double ratio = d[1] / d[0];
    for (size_t i = 1; i < d.size(); ++i) EXPECT_NEAR(d[i] / d[i - 1], ratio, 1e-12) << i;
    EXPECT_NEAR(std::pow(ratio, 47), 0.125 / 8.0, 1e-12);
    EXPECT_EQ(zoomDistances(2.0, 3.0, 1), std::vector<double>{2.0});
    const auto up = zoomDistances(0.5, 2.0, 3);  // zooming out works the same way
    EXPECT_NEAR(up[1], 1.0, 1e-12);
}

TEST(Zoom, BadInputNamesTheFlag) {
    auto msg = [](auto f) {
        try {
            f();
        } catch (const Error& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(msg([] { zoomDistances(0.0, 1.0, 4); }).find("--from"), std::string::npos);
    EXPECT_NE(msg([] { zoomDistances(1.0, -1.0, 4); }).find("--to"), std::string::npos);
    EXPECT_NE(msg([] { zoomDistances(1.0, NAN, 4); }).find("--to"), std::string::npos);
    EXPECT_NE(msg([] { zoomDistances(1.0, 2.0, 0); }).find("--frames"), std::string::npos);
    EXPECT_NE(msg([] { zoomDistances(1.0, 2.0, kMaxFrames + 1); }).find("--frames"), std::string::npos);
}

TEST(Orbit, RadiusAndHeightConstant) {
    const glm::dvec3 centre(1, 2, 3), eye(5, -1, 7), up(0, 0, 2);
    const auto eyes = orbitEyes(centre, eye, up, 360.0, 12);
    ASSERT_EQ(eyes.size(), 12u);
    EXPECT_NEAR(glm::length(eyes[0] - eye), 0.0, 1e-12);
    const double r0 = glm::length(eye - centre);
    for (const auto& e : eyes) {
        EXPECT_NEAR(glm::length(e - centre), r0, 1e-9);
        EXPECT_NEAR(e.z, eye.z, 1e-9);  // about the up axis: height kept
    }
    // Equal steps of 30° about +z (right-handed).
    const glm::dvec3 a = eyes[0] - centre, b = eyes[3] - centre;
    EXPECT_NEAR(a.x * b.x + a.y * b.y, 0.0, 1e-9);             // 90° apart in the plane
    EXPECT_GT(a.x * b.y - a.y * b.x, 0.0);                      // counter-clockwise about +z
    EXPECT_THROW(orbitEyes(centre, eye, glm::dvec3(0.0), 90.0, 4), Error);
}

std::vector<CameraKey> someKeys() {
    std::vector<CameraKey> k(4);
    k[0] = {{10, 0, 0}, {0, 0, 0}, {0, 0, 1}, 30, 0.0};
    k[1] = {{0, 10, 2}, {1, 0, 0}, {0, 0, 1}, 40, 1.0};
    k[2] = {{-8, 0, 4}, {0, 1, 0}, {0, 0.2, 1}, 20, 3.0};  // uneven spacing in time
    k[3] = {{0, -6, 0}, {0, 0, 1}, {0, 0, 1}, 25, 3.5};
    return k;
}

TEST(Keyframes, PassesThroughKeys) {
    const auto keys = someKeys();
    for (const auto& key : keys) {
        const CameraKey c = interpolate(keys, key.time);
        EXPECT_NEAR(glm::length(c.eye - key.eye), 0.0, 1e-12);
        EXPECT_NEAR(glm::length(c.lookAt - key.lookAt), 0.0, 1e-12);
        EXPECT_NEAR(glm::length(c.up - glm::normalize(key.up)), 0.0, 1e-12);
        EXPECT_NEAR(c.fovDeg, key.fovDeg, 1e-12);
    }
    // Clamped outside the range.
    EXPECT_NEAR(glm::length(interpolate(keys, -5).eye - keys[0].eye), 0.0, 1e-12);
    EXPECT_NEAR(glm::length(interpolate(keys, 99).eye - keys[3].eye), 0.0, 1e-12);
}

TEST(Keyframes, C1SmoothAtInteriorKeys) {
    const auto keys = someKeys();
    const double h = 1e-6;
    for (size_t k = 1; k + 1 < keys.size(); ++k) {
        const double t = keys[k].time;
        // One-sided derivatives from the left and right segments agree.
        const glm::dvec3 left = (interpolate(keys, t).eye - interpolate(keys, t - h).eye) / h;
        const glm::dvec3 right = (interpolate(keys, t + h).eye - interpolate(keys, t).eye) / h;
        EXPECT_NEAR(glm::length(left - right), 0.0, 1e-4 * (1.0 + glm::length(left))) << "key " << k;
        const glm::dvec3 l2 = (interpolate(keys, t).lookAt - interpolate(keys, t - h).lookAt) / h;
        const glm::dvec3 r2 = (interpolate(keys, t + h).lookAt - interpolate(keys, t).lookAt) / h;
        EXPECT_NEAR(glm::length(l2 - r2), 0.0, 1e-4 * (1.0 + glm::length(l2))) << "key " << k;
        const double lf = (interpolate(keys, t).fovDeg - interpolate(keys, t - h).fovDeg) / h;
        const double rf = (interpolate(keys, t + h).fovDeg - interpolate(keys, t).fovDeg) / h;
        EXPECT_NEAR(lf, rf, 1e-3 * (1.0 + std::abs(lf))) << "key " << k;
        // And the tangent is the Catmull–Rom one for uneven knots.
        const glm::dvec3 m = (keys[k + 1].eye - keys[k - 1].eye) / (keys[k + 1].time - keys[k - 1].time);
        EXPECT_NEAR(glm::length(left - m), 0.0, 1e-4 * (1.0 + glm::length(m))) << "key " << k;
    }
    // No jumps anywhere: small steps make small changes.
    for (double t = 0.0; t < 3.5; t += 0.01)
        EXPECT_LT(glm::length(interpolate(keys, t + 0.001).eye - interpolate(keys, t).eye), 0.1) << t;
}

TEST(Keyframes, FovStaysBetweenNeighbouringKeys) {
    const auto keys = someKeys();
    for (double t = 0.0; t <= 3.5; t += 0.01) {
        const double f = interpolate(keys, t).fovDeg;
        size_t k = 0;
        while (k + 2 < keys.size() && t > keys[k + 1].time) ++k;
        EXPECT_GE(f, std::min(keys[k].fovDeg, keys[k + 1].fovDeg) - 1e-9) << t;
        EXPECT_LE(f, std::max(keys[k].fovDeg, keys[k + 1].fovDeg) + 1e-9) << t;
    }
}

TEST(Keyframes, FrameTimes) {
    const auto keys = someKeys();
    const auto t = uniformTimes(keys, 8);
    ASSERT_EQ(t.size(), 8u);
    EXPECT_DOUBLE_EQ(t.front(), 0.0);
    EXPECT_DOUBLE_EQ(t.back(), 3.5);
    const auto r = timesAtRate(keys, 2.0);  // 0, 0.5, …, 3.5
    ASSERT_EQ(r.size(), 8u);
    EXPECT_DOUBLE_EQ(r[7], 3.5);
    EXPECT_THROW(timesAtRate(keys, 0.0), Error);
    EXPECT_THROW(timesAtRate(keys, 1e9), Error);
}

std::string errorOf(const std::string& text) {
    try {
        parseKeyframes(text, "path.json", {0, 0, 1}, 30.0);
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

TEST(Keyframes, ParsesAndDefaults) {
    const auto k = parseKeyframes(R"([{"eye":[1,2,3],"look_at":[0,0,0],"time":0},
                                      {"eye":[4,5,6],"look_at":[0,0,1],"up":[0,1,0],"fov":45,"time":2.5}])",
                                  "p.json", {0, 0, 1}, 33.0);
    ASSERT_EQ(k.size(), 2u);
    EXPECT_EQ(k[0].fovDeg, 33.0);
    EXPECT_EQ(k[0].up, glm::dvec3(0, 0, 1));
    EXPECT_EQ(k[1].up, glm::dvec3(0, 1, 0));
    EXPECT_EQ(k[1].time, 2.5);
}

TEST(Keyframes, MalformedRefusedWithOneLineNamingTheFile) {
    const std::string ok = R"("eye":[1,2,3],"look_at":[0,0,0])";
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"[]", "no keyframes"},
        {"{}", "expected a JSON array"},
        {"", "not valid JSON"},
        {"[{" + ok + ",\"time\":1},{" + ok + ",\"time\":1}]", "times must increase"},
        {"[{" + ok + ",\"time\":2},{" + ok + ",\"time\":1}]", "times must increase"},
        {"[{" + ok + ",\"time\":NaN}]", "not valid JSON"},
        {"[{" + ok + ",\"time\":1e999}]", "overflow"},
        {"[{" + ok + ",\"time\":1e20}]", "finite"},
        {"[{" + ok + "}]", "missing \"time\""},
        {R"([{"look_at":[0,0,0],"time":0}])", "missing \"eye\""},
        {"[{" + ok + ",\"time\":\"0\"}]", "expected a number"},
        {R"([{"eye":[1,2],"look_at":[0,0,0],"time":0}])", "array of 3"},
        {R"([{"eye":"1,2,3","look_at":[0,0,0],"time":0}])", "array of 3"},
        {"[{" + ok + ",\"time\":0,\"zoom\":2}]", "unknown key 'zoom'"},
        {"[{" + ok + ",\"time\":0,\"fov\":0}]", "fov"},
        {"[{" + ok + ",\"time\":0,\"up\":[0,0,0]}]", "up"},
        {"[3]", "expected an object"},
        {std::string(100000, '[') + std::string(100000, ']'), "nested deeper"},
        {"[{" + ok + ",\"time\":0,\"up\":[[[[0]]]]}]", "nested deeper"},
    };
    for (const auto& [text, needle] : cases) {
        const std::string e = errorOf(text);
        EXPECT_EQ(e.rfind("path.json", 0), 0u) << text.substr(0, 80) << " -> " << e;
        EXPECT_NE(e.find(needle), std::string::npos) << text.substr(0, 80) << " -> " << e;
        EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    }
}

}  // namespace
}  // namespace vdbsplat::animation
