// The authenticated bus: a run's key file is refused unless it
// is 32 bytes that only its owner can read; a tagged message verifies with
// its key, channel and bytes and with nothing else; a copy of a message
// already taken is dropped; bytes without a tag are dropped.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "dynhet/bus.hpp"
#include "dynhet/bus_auth.hpp"
#include "dynhet/sim_status_t.hpp"

using namespace dynhet;

namespace {

std::string temp_dir() {
  char tmpl[] = "/tmp/dynhet-bus-XXXXXX";
  const char* d = mkdtemp(tmpl);
  if (!d) throw std::runtime_error("mkdtemp");
  return d;
}

std::shared_ptr<const BusKey> key_of(unsigned seed) {
  std::array<unsigned char, BusKey::kBytes> b{};
  std::mt19937 g(seed);
  for (auto& c : b) c = static_cast<unsigned char>(g());
  return std::make_shared<const BusKey>(b);
}

std::vector<std::uint8_t> signed_message(BusSigner& s, const std::string& ch, const std::string& text) {
  std::vector<std::uint8_t> m(text.begin(), text.end());
  m.resize(text.size() + kBusTagBytes);
  s.tag(ch, m.data(), text.size());
  return m;
}

std::string load_error(const std::string& path) {
  try {
    BusKey::load(path);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

} // namespace

TEST(BusKey, CreatedKeyIsThirtyTwoBytesOnlyItsOwnerCanRead) {
  const std::string dir = temp_dir(), path = dir + "/bus.key";
  BusKey::create(path);
  struct stat s {};
  ASSERT_EQ(stat(path.c_str(), &s), 0);
  EXPECT_EQ(s.st_size, 32);
  EXPECT_EQ(s.st_mode & 0777, 0600u);
  EXPECT_EQ(load_error(path), "");
  EXPECT_THROW(BusKey::create(path), std::runtime_error); // never overwritten
  // Two keys differ (randombytes).
  BusKey::create(dir + "/other.key");
  std::ifstream a(path, std::ios::binary), b(dir + "/other.key", std::ios::binary);
  const std::string ka((std::istreambuf_iterator<char>(a)), {}), kb((std::istreambuf_iterator<char>(b)), {});
  EXPECT_NE(ka, kb);
}

TEST(BusKey, MissingEmptyShortAndOpenKeyFilesAreRefusedByName) {
  const std::string dir = temp_dir();
  EXPECT_NE(load_error(dir + "/none.key").find("none.key: cannot be opened"), std::string::npos);
  const std::string empty = dir + "/empty.key";
  { std::ofstream(empty).flush(); }
  chmod(empty.c_str(), 0600);
  EXPECT_NE(load_error(empty).find("empty"), std::string::npos) << load_error(empty);
  const std::string shortk = dir + "/short.key";
  { std::ofstream(shortk) << "0123456789"; }
  chmod(shortk.c_str(), 0600);
  EXPECT_NE(load_error(shortk).find("10 bytes, not 32"), std::string::npos) << load_error(shortk);
  const std::string open = dir + "/open.key";
  BusKey::create(open);
  chmod(open.c_str(), 0644);
  EXPECT_NE(load_error(open).find("readable or writable by others (mode 644)"), std::string::npos)
      << load_error(open);
  chmod(open.c_str(), 0620);
  EXPECT_NE(load_error(open).find("mode 620"), std::string::npos) << load_error(open);
  EXPECT_NE(load_error(dir).find("not a regular file"), std::string::npos) << load_error(dir);
}

TEST(BusTag, VerifiesWithItsKeyChannelAndBytesOnly) {
  BusSigner s(key_of(1), 5);
  BusVerifier v(key_of(1), 5), other(key_of(2), 5);
  std::size_t payload = 0;
  const auto m = signed_message(s, "DYNHET_CHI4_a0.6", "some result bytes");
  EXPECT_EQ(v.verify("DYNHET_CHI4_a0.6", m.data(), m.size(), payload), BusVerifier::Verdict::ok);
  EXPECT_EQ(payload, 17u);
  // Another key (another run), another channel, one bit changed anywhere:
  auto m2 = signed_message(s, "DYNHET_CHI4_a0.6", "some result bytes");
  EXPECT_EQ(other.verify("DYNHET_CHI4_a0.6", m2.data(), m2.size(), payload), BusVerifier::Verdict::bad_tag);
  EXPECT_EQ(v.verify("DYNHET_CHI4_a0.3", m2.data(), m2.size(), payload), BusVerifier::Verdict::bad_tag);
  for (std::size_t i = 0; i < m2.size(); i += 7) {
    if (i >= 17 && i < 21) continue; // the magic: "untagged" instead, tested below
    auto bad = m2;
    bad[i] ^= 0x10;
    EXPECT_NE(v.verify("DYNHET_CHI4_a0.6", bad.data(), bad.size(), payload), BusVerifier::Verdict::ok) << i;
  }
  // Untagged: plain LCM bytes, a short message, a wrong magic.
  const std::string plain(100, 'x');
  EXPECT_EQ(v.verify("C", plain.data(), plain.size(), payload), BusVerifier::Verdict::untagged);
  EXPECT_EQ(v.verify("C", plain.data(), 10, payload), BusVerifier::Verdict::untagged);
  auto nomagic = m2;
  nomagic[17] = 'X';
  EXPECT_EQ(v.verify("DYNHET_CHI4_a0.6", nomagic.data(), nomagic.size(), payload), BusVerifier::Verdict::untagged);
  // The genuine copy still verifies once, after all the forgeries.
  EXPECT_EQ(v.verify("DYNHET_CHI4_a0.6", m2.data(), m2.size(), payload), BusVerifier::Verdict::ok);
}

TEST(BusTag, ACopyOfAMessageTakenIsDroppedWithinAndBeyondTheWindow) {
  BusSigner s(key_of(3), 5), s2(key_of(3), 5);
  BusVerifier v(key_of(3), 5);
  std::size_t payload = 0;
  std::vector<std::vector<std::uint8_t>> sent;
  for (int i = 0; i < 3000; ++i) sent.push_back(signed_message(s, "CH", "m" + std::to_string(i)));
  // Out of order within the window: each taken once.
  for (int i : {1, 0, 3, 2, 4}) EXPECT_EQ(v.verify("CH", sent[i].data(), sent[i].size(), payload), BusVerifier::Verdict::ok) << i;
  for (int i : {0, 1, 2, 3, 4})
    EXPECT_EQ(v.verify("CH", sent[i].data(), sent[i].size(), payload), BusVerifier::Verdict::replayed) << i;
  // Far ahead, then a message that fell out of the window: dropped.
  EXPECT_EQ(v.verify("CH", sent[2999].data(), sent[2999].size(), payload), BusVerifier::Verdict::ok);
  EXPECT_EQ(v.verify("CH", sent[100].data(), sent[100].size(), payload), BusVerifier::Verdict::replayed);
  // Within the window behind the top: taken once.
  EXPECT_EQ(v.verify("CH", sent[2990].data(), sent[2990].size(), payload), BusVerifier::Verdict::ok);
  EXPECT_EQ(v.verify("CH", sent[2990].data(), sent[2990].size(), payload), BusVerifier::Verdict::replayed);
  // Another sender with the same key has its own sequence.
  const auto other = signed_message(s2, "CH", "first of another process");
  EXPECT_NE(s.sender(), s2.sender());
  EXPECT_EQ(v.verify("CH", other.data(), other.size(), payload), BusVerifier::Verdict::ok);
}

TEST(Bus, PublishedBytesAreTheLcmEncodingThenTheTag) {
  // Bus::open on both sides of the tag: the receiver's LCM bytes are the
  // sender's encoding, which safe_decode takes whole.
  auto key = key_of(4);
  Bus tx(key), rx(key), open = Bus::open_bus();
  sim_status_t m{};
  m.run_id = 42;
  m.message = "running";
  const int n = m.getEncodedSize();
  std::vector<std::uint8_t> buf(n + kBusTagBytes);
  m.encode(buf.data(), 0, n);
  BusSigner signer(key, 0);
  signer.tag("DYNHET_SIM_STATUS", buf.data(), n);
  int size = 0;
  std::string why;
  ASSERT_TRUE(rx.open("DYNHET_SIM_STATUS", buf.data(), buf.size(), size, why)) << why;
  EXPECT_EQ(size, n);
  sim_status_t back;
  EXPECT_EQ(back.decode(buf.data(), 0, size), n);
  EXPECT_EQ(back.run_id, 42);
  EXPECT_FALSE(rx.open("DYNHET_SIM_STATUS", buf.data(), buf.size(), size, why)); // the same again
  EXPECT_EQ(why.rfind("unauthenticated", 0), 0u) << why;
  EXPECT_FALSE(rx.open("DYNHET_SIM_STATUS", buf.data(), n, size, why)); // no tag
  EXPECT_TRUE(open.open("DYNHET_SIM_STATUS", buf.data(), n, size, why));
  EXPECT_EQ(size, n);
  unsetenv("DYNHET_KEY_FILE");
  EXPECT_THROW(Bus::from_options("sim_node", "", false), std::runtime_error);
  EXPECT_THROW(Bus::from_options("sim_node", "/tmp/x.key", true), std::runtime_error);
  EXPECT_FALSE(Bus::from_options("sim_node", "", true).authenticated());
  (void)tx;
}

// One message tagged by the Python side (python/dynhet/bus.py, which
// checks recorded logs for replay.sh): key 00 01 .. 1f, channel DYNHET_RUN,
// content "dynhet", epoch 3, sender 0x0102030405060708, sequence 9. The C++ side
// takes it, and the same content under another channel or sequence is not
// taken: both sides compute one function (tests/python/test_bus.py pins
// the same bytes).
TEST(BusTag, TheTagPythonComputesVerifiesHere) {
  const std::string hex = "64796e68657444485432030000000000000008070605040302010900000000000000bd9d019218b1"
                          "5947e628224db93e06ab7c44fb6df5b978ca416db44b21eb6ce0";
  std::vector<std::uint8_t> m;
  for (std::size_t i = 0; i < hex.size(); i += 2) m.push_back(static_cast<std::uint8_t>(std::stoi(hex.substr(i, 2), nullptr, 16)));
  std::array<unsigned char, BusKey::kBytes> k{};
  for (int i = 0; i < 32; ++i) k[i] = static_cast<unsigned char>(i);
  BusVerifier v(std::make_shared<const BusKey>(k), 3);
  std::size_t payload = 0;
  EXPECT_EQ(v.verify("DYNHET_FRAME", m.data(), m.size(), payload), BusVerifier::Verdict::bad_tag);
  ASSERT_EQ(v.verify("DYNHET_RUN", m.data(), m.size(), payload), BusVerifier::Verdict::ok);
  EXPECT_EQ(std::string(m.begin(), m.begin() + payload), "dynhet");
  m[6 + 4 + 8 + 8] ^= 1; // the sequence number's first byte: 9 -> 8
  EXPECT_EQ(v.verify("DYNHET_RUN", m.data(), m.size(), payload), BusVerifier::Verdict::bad_tag);
}

// Without --key-file the key comes from $DYNHET_KEY_FILE; --unauthenticated
// wins over it; a bad key file there is refused like one given by flag.
TEST(Bus, TheKeyFileComesFromTheEnvironmentUnlessTheBusIsOpenedOnPurpose) {
  char tmpl[] = "/tmp/dynhet-bus-XXXXXX";
  const std::string dir = mkdtemp(tmpl);
  BusKey::create(dir + "/bus.key");
  setenv("DYNHET_KEY_FILE", (dir + "/bus.key").c_str(), 1);
  EXPECT_TRUE(Bus::from_options("recorder", "", false).authenticated());
  EXPECT_FALSE(Bus::from_options("recorder", "", true).authenticated());
  setenv("DYNHET_KEY_FILE", (dir + "/none.key").c_str(), 1);
  try {
    Bus::from_options("recorder", "", false);
    ADD_FAILURE() << "a missing key file in $DYNHET_KEY_FILE was taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("recorder: key file " + dir + "/none.key: cannot be opened"), std::string::npos)
        << e.what();
  }
  unsetenv("DYNHET_KEY_FILE");
}

// Bus::publish and Bus::open across a real LCM instance (memq://, in
// process): the receiver gets the sender's encoding, decodes it whole, and
// takes each message once.
TEST(Bus, PublishThenOpenOverLcm) {
  auto key = key_of(9);
  Bus tx(key), rx(key);
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  struct Got {
    std::vector<std::vector<std::uint8_t>> raw;
    void on(const lcm::ReceiveBuffer* rb, const std::string&) {
      const auto* p = static_cast<const std::uint8_t*>(rb->data);
      raw.emplace_back(p, p + rb->data_size);
    }
  } got;
  lcm.subscribe("DYNHET_SIM_STATUS", &Got::on, &got);
  sim_status_t m{};
  m.run_id = 77;
  m.phase = "production";
  ASSERT_EQ(tx.publish(lcm, "DYNHET_SIM_STATUS", m), 0);
  ASSERT_EQ(tx.publish(lcm, "DYNHET_SIM_STATUS", m), 0);
  while (got.raw.size() < 2 && lcm.handleTimeout(100) > 0) {
  }
  ASSERT_EQ(got.raw.size(), 2u);
  EXPECT_EQ(got.raw[0].size(), static_cast<std::size_t>(m.getEncodedSize()) + kBusTagBytes);
  for (const auto& r : got.raw) {
    int size = 0;
    std::string why;
    ASSERT_TRUE(rx.open("DYNHET_SIM_STATUS", r.data(), r.size(), size, why)) << why;
    sim_status_t back;
    EXPECT_EQ(back.decode(r.data(), 0, size), size);
    EXPECT_EQ(back.run_id, 77);
    EXPECT_EQ(back.phase, "production");
    EXPECT_FALSE(rx.open("DYNHET_SIM_STATUS", r.data(), r.size(), size, why)); // the same bytes again: a replay
  }
}

TEST(BusTag, TheWindowsEdge) {
  BusSigner s(key_of(10), 5);
  std::vector<std::vector<std::uint8_t>> sent;
  for (int i = 0; i < 1100; ++i) sent.push_back(signed_message(s, "CH", "m" + std::to_string(i))); // sequences 1..1100
  BusVerifier v(key_of(10), 5);
  std::size_t payload = 0;
  ASSERT_EQ(v.verify("CH", sent[1099].data(), sent[1099].size(), payload), BusVerifier::Verdict::ok); // top 1100
  // 1100 - 1023 = 77 (index 76) is inside the window, 1100 - 1024 = 76 (index 75) is not.
  EXPECT_EQ(v.verify("CH", sent[76].data(), sent[76].size(), payload), BusVerifier::Verdict::ok);
  EXPECT_EQ(v.verify("CH", sent[75].data(), sent[75].size(), payload), BusVerifier::Verdict::replayed);
}

// A receiver takes only its launch's epoch (a message of an earlier segment
// of the run, replayed into the next, is refused); "any" takes all, and a
// verifier switched to another epoch takes that one's.
TEST(BusTag, OnlyThisLaunchsEpochIsTaken) {
  BusSigner earlier(key_of(11), 41), now(key_of(11), 42);
  BusVerifier v(key_of(11), 42), any(key_of(11), 0, true);
  std::size_t payload = 0;
  const auto old_msg = signed_message(earlier, "DYNHET_OVERLAP_a0.6", "a result of segment 1");
  const auto new_msg = signed_message(now, "DYNHET_OVERLAP_a0.6", "a result of segment 2");
  EXPECT_EQ(v.verify("DYNHET_OVERLAP_a0.6", old_msg.data(), old_msg.size(), payload), BusVerifier::Verdict::other_epoch);
  EXPECT_EQ(v.verify("DYNHET_OVERLAP_a0.6", new_msg.data(), new_msg.size(), payload), BusVerifier::Verdict::ok);
  EXPECT_EQ(any.verify("DYNHET_OVERLAP_a0.6", old_msg.data(), old_msg.size(), payload), BusVerifier::Verdict::ok);
  EXPECT_EQ(any.verify("DYNHET_OVERLAP_a0.6", new_msg.data(), new_msg.size(), payload), BusVerifier::Verdict::ok);
  // The epoch is under the tag: rewriting it breaks the tag.
  auto moved = old_msg;
  moved[moved.size() - kBusTagBytes + 4] = 42;
  EXPECT_EQ(v.verify("DYNHET_OVERLAP_a0.6", moved.data(), moved.size(), payload), BusVerifier::Verdict::bad_tag);
  BusVerifier w(key_of(11), 42);
  w.set_epoch(41, false);
  EXPECT_EQ(w.verify("DYNHET_OVERLAP_a0.6", old_msg.data(), old_msg.size(), payload), BusVerifier::Verdict::ok);
  EXPECT_EQ(w.verify("DYNHET_OVERLAP_a0.6", new_msg.data(), new_msg.size(), payload), BusVerifier::Verdict::other_epoch);
  std::string why;
  int size = 0;
  EXPECT_THROW(Bus::from_options("s4_node", "", true, "-3"), std::runtime_error);
  EXPECT_THROW(Bus::from_options("s4_node", "", true, "12x"), std::runtime_error);
  EXPECT_NO_THROW(Bus::from_options("s4_node", "", true, "any"));
  (void)why, (void)size;
}

// State only moves forward: on a channel that carries state, a genuine
// message older than the last one taken from its stream is dropped as
// stale, whether or not this receiver ever took it (a copy of a message
// its queue dropped, or sent before it listened).
TEST(BusTag, OlderStateIsDroppedWhateverTheWindowHolds) {
  BusSigner s(key_of(20), 5);
  BusVerifier v(key_of(20), 5);
  std::size_t payload = 0;
  const std::string ch = "DYNHET_NODE_STATUS_overlap";
  std::vector<std::vector<std::uint8_t>> sent;
  for (int i = 0; i < 10; ++i) sent.push_back(signed_message(s, ch, "status " + std::to_string(i)));
  for (int i : {0, 1, 2, 5}) EXPECT_EQ(v.verify(ch, sent[i].data(), sent[i].size(), payload), BusVerifier::Verdict::ok);
  // 3 and 4 never reached the check (a hole of 2: lost), and come now.
  EXPECT_EQ(v.drops()[static_cast<int>(BusDrop::lost)], 2);
  for (int i : {4, 3, 0, 5})
    EXPECT_EQ(v.verify(ch, sent[i].data(), sent[i].size(), payload), BusVerifier::Verdict::stale) << i;
  EXPECT_EQ(v.verify(ch, sent[9].data(), sent[9].size(), payload), BusVerifier::Verdict::ok);
  EXPECT_EQ(v.verify(ch, sent[8].data(), sent[8].size(), payload), BusVerifier::Verdict::stale);
  const auto d = v.drops();
  EXPECT_EQ(d[static_cast<int>(BusDrop::stale)], 5);
  EXPECT_EQ(d[static_cast<int>(BusDrop::lost)], 2 + 3); // 6, 7, 8 never came in order
  EXPECT_EQ(d[static_cast<int>(BusDrop::replayed)], 0);
  for (const char* c : {"DYNHET_RUN", "DYNHET_SIM_STATUS", "DYNHET_NODE_STATUS_s4", "DYNHET_CHECKPOINT",
                        "DYNHET_CHECKPOINT_recorder"})
    EXPECT_TRUE(carries_state(c)) << c;
  for (const char* c : {"DYNHET_FRAME", "DYNHET_OVERLAP_a0.6", "DYNHET_RUNX", "DYNHET_CHECKPOINTS", "CH"})
    EXPECT_FALSE(carries_state(c)) << c;
}

// A sender numbers its messages per channel: the streams are apart, a
// hole is per stream, and a late message of a results channel that fills
// a hole is taken once and is no longer counted lost.
TEST(BusTag, EachChannelIsItsOwnStreamAndItsHolesAreCountedLost) {
  BusSigner s(key_of(21), 5);
  BusVerifier v(key_of(21), 5);
  std::size_t payload = 0;
  std::vector<std::vector<std::uint8_t>> a, b;
  for (int i = 0; i < 5; ++i) {
    a.push_back(signed_message(s, "DYNHET_OVERLAP_a1", "a" + std::to_string(i)));
    b.push_back(signed_message(s, "DYNHET_SIM_STATUS", "b" + std::to_string(i)));
  }
  for (int i : {0, 1, 3}) EXPECT_EQ(v.verify("DYNHET_OVERLAP_a1", a[i].data(), a[i].size(), payload), BusVerifier::Verdict::ok);
  for (int i : {0, 1, 2, 3, 4})
    EXPECT_EQ(v.verify("DYNHET_SIM_STATUS", b[i].data(), b[i].size(), payload), BusVerifier::Verdict::ok) << i;
  EXPECT_EQ(v.drops()[static_cast<int>(BusDrop::lost)], 1);
  EXPECT_EQ(v.verify("DYNHET_OVERLAP_a1", a[2].data(), a[2].size(), payload), BusVerifier::Verdict::ok); // late
  EXPECT_EQ(v.drops()[static_cast<int>(BusDrop::lost)], 0);
  EXPECT_EQ(v.verify("DYNHET_OVERLAP_a1", a[2].data(), a[2].size(), payload), BusVerifier::Verdict::replayed);
  // Every refusal counted by its reason.
  const std::vector<std::uint8_t> untagged(a[4].begin(), a[4].end() - kBusTagBytes);
  std::vector<std::uint8_t> altered = a[4];
  altered[0] ^= 1;
  EXPECT_EQ(v.verify("DYNHET_OVERLAP_a1", untagged.data(), untagged.size(), payload), BusVerifier::Verdict::untagged);
  EXPECT_EQ(v.verify("DYNHET_OVERLAP_a1", altered.data(), altered.size(), payload), BusVerifier::Verdict::bad_tag);
  EXPECT_EQ(v.verify("DYNHET_OVERLAP_a0.6", a[4].data(), a[4].size(), payload), BusVerifier::Verdict::bad_tag);
  const auto d = v.drops();
  EXPECT_EQ(d[static_cast<int>(BusDrop::untagged)], 1);
  EXPECT_EQ(d[static_cast<int>(BusDrop::bad_tag)], 2);
  EXPECT_EQ(d[static_cast<int>(BusDrop::replayed)], 1);
  EXPECT_STREQ(bus_drop_name(BusDrop::queue_full), "queue_full");
}
