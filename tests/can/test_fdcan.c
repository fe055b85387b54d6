/* SPDX-License-Identifier: MIT */
/* The STM32G4 FDCAN driver against a register file and message RAM in plain memory: bit timing, the
 * configuration it writes, the element layout of TX and RX, FIFO indices, bus-off recovery. */
#include <string.h>

#include "fdcan.h"
#include "unity.h"

static uint32_t regs[POUR_FDCAN_N_REGS];
static uint32_t ram[POUR_FDCAN_RAM_WORDS];
static pour_fdcan_t can;

static pour_fdcan_hw_t fake_hw(void) {
  pour_fdcan_hw_t hw = {regs, ram};
  return hw;
}

void setUp(void) {
  memset(regs, 0, sizeof regs);
  memset(ram, 0xA5, sizeof ram);
  pour_fdcan_config_t c = pour_fdcan_default_config();
  c.node_id = 3;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_fdcan_init(&can, fake_hw(), &c));
}

void tearDown(void) {}

static void test_fdcan_timing_Gives87PercentSamplePointAt1Mbit(void) {
  pour_fdcan_timing_t t;
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_fdcan_timing(16000000u, 1000000u, &t));
  TEST_ASSERT_EQUAL_UINT16(1, t.prescaler);
  TEST_ASSERT_EQUAL_UINT8(13, t.tseg1);
  TEST_ASSERT_EQUAL_UINT8(2, t.tseg2);
  TEST_ASSERT_EQUAL_UINT8(2, t.sjw);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_fdcan_timing(170000000u, 1000000u, &t));
  TEST_ASSERT_EQUAL_UINT16(10, t.prescaler);
  TEST_ASSERT_EQUAL_UINT32(17, 1u + t.tseg1 + t.tseg2);
  TEST_ASSERT_EQUAL_INT(POUR_OK, pour_fdcan_timing(80000000u, 500000u, &t));
  TEST_ASSERT_EQUAL_UINT32(80000000u, (uint32_t)t.prescaler * (1u + t.tseg1 + t.tseg2) * 500000u);
}

static void test_fdcan_timing_RefusesInexactOrTooFastRates(void) {
  pour_fdcan_timing_t t;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_fdcan_timing(16500000u, 1000000u, &t));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_fdcan_timing(4000000u, 1000000u, &t));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_fdcan_timing(16000000u, 0u, &t));
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_fdcan_timing(16000000u, 1000000u, NULL));
}

static void test_fdcan_init_WritesClassicModeTimingAndOneFilter(void) {
  TEST_ASSERT_EQUAL_HEX32(0, regs[POUR_FDCAN_CCCR] & 0x3FFu); /* running, classic, no CCE, no test */
  /* NSJW 1, NBRP 0, NTSEG1 12, NTSEG2 1 */
  TEST_ASSERT_EQUAL_HEX32((1u << 25) | (0u << 16) | (12u << 8) | 1u, regs[POUR_FDCAN_NBTP]);
  /* classic filter, FIFO 0, id 3 << 5, mask 0x7E0 */
  TEST_ASSERT_EQUAL_HEX32((2u << 30) | (1u << 27) | (0x060u << 16) | 0x7E0u, ram[0]);
  TEST_ASSERT_EQUAL_HEX32(0, ram[1]); /* the rest of the message RAM is cleared */
  TEST_ASSERT_EQUAL_HEX32(0, ram[POUR_FDCAN_RAM_WORDS - 1u]);
  /* LSS 1, FIFO 0 overwrite, reject non-matching and remote frames */
  TEST_ASSERT_EQUAL_HEX32((1u << 16) | (1u << 9) | (2u << 4) | (2u << 2) | 3u, regs[POUR_FDCAN_RXGFC]);
  TEST_ASSERT_EQUAL_HEX32(0, regs[POUR_FDCAN_TXBC]);
}

static void test_fdcan_init_RefusesBadConfig(void) {
  pour_fdcan_config_t c = pour_fdcan_default_config();
  c.node_id = 64;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_fdcan_init(&can, fake_hw(), &c));
  c = pour_fdcan_default_config();
  c.kernel_clock_hz = 16500000u;
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_fdcan_init(&can, fake_hw(), &c));
  c = pour_fdcan_default_config();
  pour_fdcan_hw_t none = {NULL, ram};
  TEST_ASSERT_EQUAL_INT(POUR_EINVAL, pour_fdcan_init(&can, none, &c));
}

static void test_fdcan_transmit_FillsElementAtPutIndexAndRequestsIt(void) {
  regs[POUR_FDCAN_TXFQS] = 2u << 16; /* put index 2 */
  pour_can_frame_t f = {.id = 0x072, .dlc = 7, .data = {1, 2, 3, 4, 5, 6, 7, 0}};
  TEST_ASSERT_EQUAL_INT(0, pour_fdcan_transmit(&can, &f));
  const uint32_t *e = &ram[POUR_FDCAN_RAM_TXQ + 2u * POUR_FDCAN_ELEMENT_WORDS];
  TEST_ASSERT_EQUAL_HEX32(0x072u << 18, e[0]);
  TEST_ASSERT_EQUAL_HEX32(7u << 16, e[1]);
  TEST_ASSERT_EQUAL_HEX32(0x04030201u, e[2]);
  TEST_ASSERT_EQUAL_HEX32(0x00070605u, e[3]);
  TEST_ASSERT_EQUAL_HEX32(1u << 2, regs[POUR_FDCAN_TXBAR]);
  TEST_ASSERT_EQUAL_UINT32(1, can.tx_frames);
}

static void test_fdcan_transmit_CountsAFullFifo(void) {
  regs[POUR_FDCAN_TXFQS] = 1u << 21;
  pour_can_frame_t f = {.id = 0x072, .dlc = 7, .data = {0}};
  TEST_ASSERT_EQUAL_INT(-1, pour_fdcan_transmit(&can, &f));
  TEST_ASSERT_EQUAL_UINT32(1, can.tx_full);
  TEST_ASSERT_EQUAL_HEX32(0, regs[POUR_FDCAN_TXBAR]);
}

static void put_rx(unsigned index, uint32_t e0, uint32_t e1, uint32_t d0, uint32_t d1) {
  uint32_t *e = &ram[POUR_FDCAN_RAM_RF0 + index * POUR_FDCAN_ELEMENT_WORDS];
  e[0] = e0;
  e[1] = e1;
  e[2] = d0;
  e[3] = d1;
}

static void test_fdcan_receive_ReadsGetIndexAndAcknowledges(void) {
  pour_can_frame_t f;
  TEST_ASSERT_EQUAL_INT(0, pour_fdcan_receive(&can, &f)); /* empty */
  put_rx(1, 0x071u << 18, (8u << 16) | 0x1234u, 0x44332211u, 0x88776655u);
  regs[POUR_FDCAN_RXF0S] = (1u << 8) | 1u; /* get index 1, fill level 1 */
  regs[POUR_FDCAN_RXF0A] = 0xFFu;
  TEST_ASSERT_EQUAL_INT(1, pour_fdcan_receive(&can, &f));
  TEST_ASSERT_EQUAL_HEX16(0x071, f.id);
  TEST_ASSERT_EQUAL_UINT8(8, f.dlc);
  const uint8_t want[8] = {0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88};
  TEST_ASSERT_EQUAL_HEX8_ARRAY(want, f.data, 8);
  TEST_ASSERT_EQUAL_HEX32(1, regs[POUR_FDCAN_RXF0A]);
}

static void test_fdcan_receive_SkipsExtendedRemoteAndFdFrames(void) {
  pour_can_frame_t f;
  regs[POUR_FDCAN_RXF0S] = 1u; /* the fake never drains: every read sees the same element */
  put_rx(0, (1u << 30) | 0x71u, 8u << 16, 0, 0);
  TEST_ASSERT_EQUAL_INT(0, pour_fdcan_receive(&can, &f));
  put_rx(0, (1u << 29) | (0x71u << 18), 0, 0, 0);
  TEST_ASSERT_EQUAL_INT(0, pour_fdcan_receive(&can, &f));
  put_rx(0, 0x71u << 18, (1u << 21) | (8u << 16), 0, 0);
  TEST_ASSERT_EQUAL_INT(0, pour_fdcan_receive(&can, &f));
  TEST_ASSERT_EQUAL_UINT32(3u * POUR_FDCAN_FIFO_ELEMENTS, can.rx_rejected);
  TEST_ASSERT_EQUAL_UINT32(0, can.rx_frames);
}

static void test_fdcan_poll_RecoversFromBusOffAndCountsLostFrames(void) {
  TEST_ASSERT_EQUAL_INT(0, pour_fdcan_poll(&can));
  regs[POUR_FDCAN_PSR] = 1u << 7;    /* bus-off */
  regs[POUR_FDCAN_CCCR] |= 1u;       /* the peripheral set INIT */
  regs[POUR_FDCAN_RXF0S] = 1u << 25; /* a message was lost */
  TEST_ASSERT_EQUAL_INT(1, pour_fdcan_poll(&can));
  TEST_ASSERT_EQUAL_HEX32(0, regs[POUR_FDCAN_CCCR] & 1u);
  TEST_ASSERT_EQUAL_UINT32(1, can.bus_off);
  TEST_ASSERT_EQUAL_UINT32(1, can.rx_lost);
  TEST_ASSERT_EQUAL_HEX32(1u << 2, regs[POUR_FDCAN_IR]);
}

int main(void) {
  UNITY_BEGIN();
  RUN_TEST(test_fdcan_timing_Gives87PercentSamplePointAt1Mbit);
  RUN_TEST(test_fdcan_timing_RefusesInexactOrTooFastRates);
  RUN_TEST(test_fdcan_init_WritesClassicModeTimingAndOneFilter);
  RUN_TEST(test_fdcan_init_RefusesBadConfig);
  RUN_TEST(test_fdcan_transmit_FillsElementAtPutIndexAndRequestsIt);
  RUN_TEST(test_fdcan_transmit_CountsAFullFifo);
  RUN_TEST(test_fdcan_receive_ReadsGetIndexAndAcknowledges);
  RUN_TEST(test_fdcan_receive_SkipsExtendedRemoteAndFdFrames);
  RUN_TEST(test_fdcan_poll_RecoversFromBusOffAndCountsLostFrames);
  return UNITY_END();
}
