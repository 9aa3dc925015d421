/*
 * board.h: the board layer of the gyrocal example firmware. A port (Arduino, STM32 HAL, Pico SDK, a
 * host test) provides these functions; everything else is portable C99.
 */
#ifndef GYROCAL_EXAMPLE_BOARD_H
#define GYROCAL_EXAMPLE_BOARD_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Wait until the next sample is due, then read the gyro and the accelerometer [counts] and the
 * temperature [0.01 degC] (GYROCAL_TEMP_NONE without one). A board without an accelerometer leaves
 * accel alone (the firmware sends it only when set up with an accelerometer sensitivity). Returns 0,
 * or non-zero when there are no more samples (a host test's simulated session ends; real boards never end). */
int board_read(int16_t gyro[3], int16_t accel[3], int16_t *temp_centi);
/* Send n bytes to the host (a UART, USB CDC); may block while the transmit buffer is full. */
void board_write(const uint8_t *data, size_t n);
/* Free-running clocks since power-up [us] and [ms], wrapping at 2^32. */
uint32_t board_micros(void);
uint32_t board_millis(void);
/* Bytes the host sent (`gyrocal capture --write-back`), without waiting: up to cap of them into data; returns how
 * many (0: none yet). A board that never listens returns 0. */
size_t board_receive(uint8_t *data, size_t cap);
/* The calibration's storage (a flash page, an EEPROM): write n bytes, or read n bytes back; 0 on success. The
 * firmware reads back what it wrote and answers the host with that, so a write that did not take shows. */
int board_store(const uint8_t *data, size_t n);
int board_load(uint8_t *data, size_t n);

#ifdef __cplusplus
}
#endif

#endif
