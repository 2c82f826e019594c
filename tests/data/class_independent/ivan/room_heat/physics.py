# Simple room model used by the thermometer node (kept apart so I can test it without ROS)


def nextRoomTemperature(currentTemp, outsideTemp, heaterOn, dt):
    # Newton cooling towards the outside plus a constant heat input when the heater is on
    lossRate = 0.05
    heatingRate = 0.8
    change = -lossRate * (currentTemp - outsideTemp)
    if heaterOn:
        change = change + heatingRate
    return currentTemp + change * dt
